"""Figures: what ``.plot()`` draws and ``ax.figure.savefig(...)`` writes keeps its title,
axis labels and legend inside the image (in the figures the library makes and in Axes the
caller made); ``Shape.plot`` and ``World.plot`` draw the bodies; without matplotlib every
``plot`` says in one line how to install it."""

from __future__ import annotations

import io
import sys

import numpy as np
import pytest

import polycontact as pc

plt = pytest.importorskip("matplotlib.pyplot")

SQ = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
TALL = [(0.0, 0.0), (1.0, 0.0), (1.0, 30.0), (0.0, 30.0)]
WIDE = [(0.0, 0.0), (30.0, 0.0), (30.0, 1.0), (0.0, 1.0)]


def _world() -> pc.World:
    w = pc.World(container=[(0, 0), (5, 0), (5, 2), (0, 2)])
    w.add(SQ, (0.5, 0.5), name="left")
    w.add(SQ, (1.5, 0.5))
    w.add([(0, 0), (1, 0), (0, 1)], (4.8, 1.0), name="out")
    return w


def _plots(offset: float, scale: float) -> dict:
    """``name -> () -> Axes`` for every figure a result or a body draws, bodies scaled by
    ``scale`` and moved by ``offset``."""
    def at(ring):
        return np.asarray(ring) * scale + offset

    a, b = pc.Shape(at(TALL)), pc.Shape(at([(0.5, 1.0), (3.0, 1.0), (3.0, 3.0)]))
    sq = pc.Shape(at(SQ))
    bin_ = pc.Shape(at([(0, 0), (4, 0), (4, 2), (0, 2)]))
    return {
        "Relation": lambda: pc.classify(a, b).plot(),
        "Relation-wide": lambda: pc.classify(pc.Shape(at(WIDE)), b).plot(),
        "Impact": lambda: pc.time_of_impact(
            sq, pc.Motion(velocity=(scale, 0.0)), sq.moved((3 * scale, 0.0)),
            pc.Motion(angular_velocity=1.0), t_max=5.0).plot(),
        "NoFitPolygon": lambda: pc.no_fit_polygon(a, pc.Shape(at(WIDE))).plot(),
        "inner fit": lambda: _inner_fit(sq, bin_),
        "Contacts": lambda: _world().contacts().plot(),
        "Shape": lambda: a.plot(numbers=True, label="A"),
        "World": lambda: _world().plot(),
        "EntranceBlock": lambda: pc.entrance_block(sq, sq.moved((3 * scale, 0.0))).plot(),
    }


def _inner_fit(a: pc.Shape, container: pc.Shape):
    from polycontact.plotting import plot_inner_fit

    return plot_inner_fit(a, container, pc.inner_fit_polygon(a, container, "origin"), (0, 0))


def _outside(ax) -> list[str]:
    """The texts and legend of ``ax`` that the saved image would cut (by their window
    extents, after a draw at the saving resolution)."""
    fig = ax.figure
    fig.savefig(io.BytesIO(), format="png", dpi=100)
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    items = {"title": ax.title, "x label": ax.xaxis.label, "y label": ax.yaxis.label,
             "legend": ax.get_legend(), **{f"figure legend {k}": legend
                                           for k, legend in enumerate(fig.legends)}}
    cut = []
    for name, artist in items.items():
        if artist is None or not artist.get_visible():
            continue
        e = artist.get_window_extent(renderer)
        if e.x0 < box.x0 - 0.5 or e.y0 < box.y0 - 0.5 or e.x1 > box.x1 + 0.5 or \
                e.y1 > box.y1 + 0.5:
            cut.append(f"{name} {e.extents.round(1).tolist()} beyond {box.extents.tolist()}")
    return cut


@pytest.mark.parametrize(("offset", "scale"), [(0.0, 1.0), (1e9, 1.0), (-5e5, 1e-3),
                                               (0.0, 1e6)])
@pytest.mark.parametrize("name", list(_plots(0.0, 1.0)))
def test_a_saved_figure_keeps_its_title_labels_and_legend(name, offset, scale):
    ax = _plots(offset, scale)[name]()
    try:
        panels = ax.figure.axes  # (an entrance block: four, labelled on the outer edges)
        for panel in panels:
            assert _outside(panel) == [], (name, panel.get_title())
        assert any(p.get_xlabel() for p in panels) and any(p.get_ylabel() for p in panels)
    finally:
        plt.close(ax.figure)


@pytest.mark.parametrize("name", ["Relation", "Contacts", "NoFitPolygon", "World", "Impact"])
def test_a_plot_into_the_callers_plain_axes_keeps_its_legend_in_the_image(name):
    fig, ax = plt.subplots()  # no layout engine: a legend outside the axes would be cut
    try:
        sq = pc.Shape(SQ)
        draw = {
            "Relation": lambda: pc.classify(TALL, WIDE).plot(ax=ax),
            "Contacts": lambda: _world().contacts().plot(ax=ax),
            "NoFitPolygon": lambda: pc.no_fit_polygon(sq, sq.moved((3, 0))).plot(ax=ax),
            "World": lambda: _world().plot(ax=ax),
            "Impact": lambda: pc.time_of_impact(sq, pc.Motion(velocity=(1, 0)),
                                                sq.moved((3, 0)), pc.Motion(),
                                                t_max=5).plot(ax=ax),
        }[name]
        assert draw() is ax
        assert ax.get_legend() is not None
        assert _outside(ax) == []
    finally:
        plt.close(fig)


def _colour_at(ax, xy) -> tuple:
    """The colour of the drawn figure at data point ``xy``."""
    ax.set_xlim(-2, 5)
    ax.set_ylim(-2, 5)
    fig = ax.figure
    fig.canvas.draw()
    x, y = ax.transData.transform(xy)
    image = np.asarray(fig.canvas.buffer_rgba())
    return tuple(image[image.shape[0] - 1 - int(round(y)), int(round(x))].tolist())


def test_shape_plot_draws_the_loops_and_the_callers_vertex_numbers():
    # given clockwise: stored reversed, numbered as given
    shape = pc.Shape([(0, 0), (0, 4), (4, 4), (4, 0)], [[(1, 1), (2, 1), (2, 2)]])
    ax = shape.plot(numbers=True, facecolor="tab:orange")
    try:
        texts = {t.get_text(): tuple(t.xy) for t in ax.texts}
        assert texts == {"0": (0.0, 0.0), "1": (0.0, 4.0), "2": (4.0, 4.0), "3": (4.0, 0.0),
                         "1:0": (1.0, 1.0), "1:1": (2.0, 1.0), "1:2": (2.0, 2.0)}
        (patch,) = ax.patches
        assert _colour_at(ax, (3.0, 3.0)) != _colour_at(ax, (-1.0, -1.0))  # the solid
        assert _colour_at(ax, (1.8, 1.2)) == _colour_at(ax, (-1.0, -1.0))  # the open hole
        assert ax.get_title() == "4 vertices, 1 hole, area 15.5"
        assert ax.get_legend() is None
    finally:
        plt.close(ax.figure)


def test_shape_plot_marks_the_vertices_repair_made_as_new():
    shape = pc.Shape([(0, 0), (2, 0), (2, 2), (1, 2), (1, 3), (1, 2), (0, 2)], repair=True)
    ax = shape.plot(numbers=True)
    try:
        assert sorted(t.get_text() for t in ax.texts) == sorted(
            str(shape.input_vertex(0, i)) if shape.input_vertex(0, i) is not None else "new"
            for i in range(len(shape.exterior)))
    finally:
        plt.close(ax.figure)


def test_world_plot_draws_every_body_where_it_stands_with_its_id():
    w = _world()
    w.move(1, (2.5, 1.0), angle=0.3)
    ax = w.plot()
    try:
        assert ax.get_title() == "3 bodies, in a container"
        labels = {t.get_text(): tuple(t.xy) for t in ax.texts}
        assert set(labels) == {"0 (left)", "1", "2 (out)"}
        assert labels["1"] == pytest.approx((2.5, 1.0))
        drawn = [p.get_path().vertices[:-1] for p in ax.patches[1:]]
        for body, verts in zip(w.bodies(), drawn):
            assert np.allclose(verts, np.vstack(body.shape.loops))
        assert ax.get_legend_handles_labels()[1] == ["container", "bodies"]
        assert not w.plot(labels=False).texts
    finally:
        plt.close("all")


def test_a_large_world_is_drawn_without_ids_unless_asked():
    from polycontact.plotting.world import LABELLED_BODIES

    w = pc.World()
    w.add_many([SQ] * (LABELLED_BODIES + 1))
    try:
        assert len(w.plot().texts) == 0
        assert len(w.plot(labels=True).texts) == LABELLED_BODIES + 1
    finally:
        plt.close("all")


def test_an_empty_world_is_drawn():
    ax = pc.World().plot()
    try:
        assert ax.get_title() == "0 bodies" and ax.get_legend() is None
    finally:
        plt.close(ax.figure)


PLOT_CALLS = {
    "Shape.plot": lambda: pc.Shape(SQ).plot(),
    "World.plot": lambda: _world().plot(),
    "Relation.plot": lambda: pc.classify(SQ, TALL).plot(),
    "Contacts.plot": lambda: _world().contacts().plot(),
    "NoFitPolygon.plot": lambda: pc.no_fit_polygon(SQ, TALL).plot(),
    "Impact.plot": lambda: pc.time_of_impact(SQ, pc.Motion(), TALL, pc.Motion(),
                                             t_max=1).plot(),
    "EntranceBlock.plot": lambda: pc.entrance_block(SQ, TALL).plot(),
}


@pytest.mark.parametrize("call", list(PLOT_CALLS))
def test_plot_without_matplotlib_says_in_one_line_how_to_install_it(monkeypatch, call):
    for name in list(sys.modules):
        if name == "matplotlib" or name.startswith("matplotlib."):
            monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as after a plain `pip install .`
    with pytest.raises(ImportError) as err:
        PLOT_CALLS[call]()
    message = str(err.value)
    assert "\n" not in message and message.endswith("pip install 'polycontact[plot]'")
    assert "matplotlib" in message
