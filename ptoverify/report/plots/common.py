"""What every figure module shares: new figures, PNG files, styles, axis finishing.

A figure is a :class:`matplotlib.figure.Figure` made directly (no pyplot, so no
backend is chosen or switched and nothing is registered to close) with
constrained layout, and written by :meth:`~matplotlib.figure.Figure.savefig`:
Matplotlib's own PNG writer, whatever backend the caller uses.  :func:`write_png`
runs the layout once itself and gives such a figure an Agg canvas first, so that
the layout and the drawing share one renderer (savefig would draw once more just
to run the layout, on a renderer of its own): the same pixels at about three
quarters of the CPU (issue 23, all 35 report figures compared pixel by pixel).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.backend_bases import FigureCanvasBase
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ptoverify.config import Plant
from ptoverify.model.curves import level_curve_x1
from ptoverify.model.laws import Region
from ptoverify.report.words import law_name

if TYPE_CHECKING:  # data types for annotations only
    from matplotlib.axes import Axes

    from ptoverify.sim.simulate import SimResult

#: Resolution of the written PNGs [1/inch].
DPI = 110
#: Size of a single-panel figure [inch].
SIZE = (6.4, 4.2)
#: rcParams while a PNG is written: unhinted glyphs (as in Matplotlib's own image
#: tests), about a fifth less CPU for the report's figures than the TrueType hinter.
RENDER_RC = {"text.hinting": "no_hinting"}
#: Pillow's options for the PNG files: zlib level 1, the same pixels in about half the
#: encoding time of the default level 6 (the files about 7 % larger).
PNG_OPTIONS = {"compress_level": 1}
#: Line style of each law in the response figures.
STYLE = {
    "to": dict(color="tab:red", lw=1.0, label=law_name("to")),
    "pd": dict(color="tab:blue", lw=1.3, label=law_name("pd")),
    "pto": dict(color="tab:green", lw=1.6, label=law_name("pto")),
    "pto-printed": dict(color="tab:orange", lw=1.2, ls="--", label=law_name("pto-printed")),
}
#: Colour and legend label of each region of the PTO law (Fig. 6).
REGION_STYLE = {
    Region.BANG_P: ("tab:red", "S_P: +w_max"),
    Region.BANG_N: ("tab:purple", "S_N: -w_max"),
    Region.ZONE_P: ("tab:orange", "zone: +omega_c"),
    Region.ZONE_N: ("tab:olive", "zone: -omega_c"),
    Region.LINEAR: ("tab:green", "linear zone"),
    Region.SATURATED: ("tab:cyan", "linear, clipped"),
    Region.ORIGIN: ("k", "origin"),
}
#: Phase-plane arcs: (x1 [mm], x2 [mm/s]), each of shape (n_t, n_traj).
Arcs = tuple[NDArray[np.float64], NDArray[np.float64]]


def new_figure(size: tuple[float, float] = SIZE) -> Figure:
    """Make an empty figure outside pyplot, with constrained layout.

    Parameters
    ----------
    size : tuple of float
        Width and height [inch].

    Returns
    -------
    Figure
        The figure (:data:`DPI` dots per inch).

    Examples
    --------
    >>> new_figure((3.0, 2.0)).get_size_inches().tolist()
    [3.0, 2.0]
    """
    return Figure(figsize=size, dpi=DPI, layout="constrained")


def new_axes(ax: Axes | None = None, size: tuple[float, float] = SIZE) -> Axes:
    """Return ``ax``, or the one axes of a new figure when it is None.

    Parameters
    ----------
    ax : matplotlib Axes, optional
        Axes the caller chose.
    size : tuple of float
        Size of the new figure [inch] (when ``ax`` is None).

    Returns
    -------
    matplotlib Axes
        Where to draw.
    """
    return new_figure(size).add_subplot() if ax is None else ax


def write_png(fig: Figure, path: str | Path) -> Path:
    """Write a figure as a PNG with Matplotlib's writer (``Figure.savefig``).

    Layout and drawing run under :data:`RENDER_RC` (an rcParams context: the
    caller's settings are back afterwards).  The figure's layout engine runs once
    here and is then removed (the axes keep the positions it gave them), so the
    figure is drawn once; a figure still on the base canvas of :func:`new_figure`
    gets an Agg canvas, whose one renderer serves the layout and the drawing.

    Parameters
    ----------
    fig : Figure
        The figure drawn on.
    path : str or Path
        The file to write (its folder must exist).

    Returns
    -------
    Path
        The file written.
    """
    if type(fig.canvas) is FigureCanvasBase:  # a figure of new_figure: an Agg canvas, so
        FigureCanvasAgg(fig)  # that the layout and the PNG share one renderer (text metrics)
    with matplotlib.rc_context(RENDER_RC):
        engine = fig.get_layout_engine()
        if engine is not None:
            # the layout once, then no engine: savefig would otherwise traverse the
            # whole figure once more (a draw with rendering disabled) just to run it
            engine.execute(fig)
            fig.set_layout_engine("none")  # not None: that reads the rcParams
        fig.savefig(path, format="png", dpi=DPI, pil_kwargs=PNG_OPTIONS)
    return Path(path)


def save_drawing(
    path: str | Path, draw: Callable[[Figure], object], size: tuple[float, float] = SIZE
) -> Path:
    """Draw on a new figure and write it as a PNG.

    Parameters
    ----------
    path : str or Path
        The file to write (its folder must exist).
    draw : callable
        ``draw(fig)`` adds the axes to the empty figure and draws on them.
    size : tuple of float
        Figure size [inch].

    Returns
    -------
    Path
        The file written.
    """
    fig = new_figure(size)
    draw(fig)
    return write_png(fig, path)


def save_figure(
    path: str | Path, draw: Callable[[Axes], object], size: tuple[float, float] = SIZE
) -> Path:
    """Draw on the one axes of a new figure and write it as a PNG.

    Parameters
    ----------
    path : str or Path
        The file to write (its folder must exist).
    draw : callable
        ``draw(ax)`` draws on the figure's axes.
    size : tuple of float
        Figure size [inch].

    Returns
    -------
    Path
        The file written.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     save_figure(f"{d}/line.png", lambda ax: ax.plot([0, 1])).read_bytes()[1:4]
    b'PNG'
    """
    return save_drawing(path, lambda fig: draw(fig.add_subplot()), size)


def folder(outdir: str | Path) -> Path:
    """Create a folder for figures if missing.

    Parameters
    ----------
    outdir : str or Path
        The folder.

    Returns
    -------
    Path
        The folder.
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    return outdir


def finish(
    ax: Axes,
    title: str,
    xlab: str = "position $x_1$ [mm]",
    ylab: str = "velocity $x_2$ [mm/s]",
) -> None:
    """Label the axes (units in brackets), title them, add a grid and a legend.

    Parameters
    ----------
    ax : matplotlib Axes
        The axes drawn on.
    title : str
        The title.
    xlab, ylab : str
        Axis labels, each with its unit.
    """
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    inner_legend(ax, fontsize=7, loc="best")


def inner_legend(ax: Axes, *args, **kwargs):
    """Add a legend placed inside the axes, left out of the layout (it cannot widen it).

    The layout engines measure every artist that takes part in the layout, and a
    legend's box is costly to measure; one inside the axes never moves their edge,
    so leaving it out changes no pixel (the report's 35 figures compared one by one).

    Parameters
    ----------
    ax : matplotlib Axes
        The axes.
    *args, **kwargs
        Those of :meth:`matplotlib.axes.Axes.legend` (a location inside the axes).

    Returns
    -------
    matplotlib.legend.Legend
        The legend.
    """
    legend = ax.legend(*args, **kwargs)
    legend.set_in_layout(False)
    return legend


def level_curve(ax: Axes, a: float, omega: float, x2, drawn: dict, label: str, **kw) -> None:
    """Draw the level curve of eq. (9) at speed ``omega`` and record it in ``drawn``.

    Parameters
    ----------
    ax : matplotlib Axes
        Where to draw.
    a : float
        Plant bandwidth [rad/s].
    omega : float
        Speed of the curve (w_max for l1, omega0 for l1*) [mm/s].
    x2 : array_like
        Velocities on the curve [mm/s].
    drawn : dict
        Label -> artist; the line is added under ``label``.
    label : str
        Legend label.
    **kw
        Line properties.
    """
    (line,) = ax.plot(level_curve_x1(x2, a, omega), x2, label=label, **kw)
    drawn[label] = line


def switching_curves(ax: Axes, plant: Plant, drawn: dict, *, lim: float | None = None) -> None:
    """Draw l1 (x2 <= 0, eq. 9) and l2 (x2 >= 0, eq. 11).

    Parameters
    ----------
    ax : matplotlib Axes
        Where to draw.
    plant : Plant
        Plant (a [rad/s], w_max [mm/s]).
    drawn : dict
        Label -> artist; both curves are added.
    lim : float, optional
        Largest |x2| drawn [mm/s] (default w_max).
    """
    a, w = plant.a, plant.w_max
    top = w if lim is None else lim
    neg, pos = np.linspace(-top, 0, 300), np.linspace(0, top, 300)
    level_curve(ax, a, w, neg, drawn, "l1 (eq. 9), x2 <= 0", color="k", lw=1.8)
    level_curve(ax, a, w, pos, drawn, "l2 (eq. 11), x2 >= 0", color="k", lw=1.8, ls="-.")


def tracking(res: SimResult) -> str:
    """Name a response's tracking reading for titles.

    Parameters
    ----------
    res : SimResult
        A response.

    Returns
    -------
    str
        ``feed-forward`` or ``no feed-forward``.
    """
    return "feed-forward" if res.feedforward else "no feed-forward"
