"""Figures of a simulation (paths, velocities, accelerations, reactions) and an animation
of the mechanism with its point paths.

Every function draws on the Axes/Figure it is given (a new pyplot one otherwise) and
returns it; none writes a file or chooses a backend.
"""

from __future__ import annotations

from typing import Any

import matplotlib
import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io.pyslvs import color_rgb
from mechsyn.model.pairs import belt_tangent
from mechsyn.plot._base import axes, figure

__all__ = ["animate_simulation", "draw_mechanism", "link_outlines", "plot_forces", "plot_paths",
           "plot_simulation"]


def _joint_point_on(j, link: str) -> np.ndarray:
    """The joint's point on ``link``: a belt's anchor on its first link, else its point."""
    if j.type == "belt" and j.links[0] == link:
        return np.asarray(j.attrs["anchor"], float)
    return j.point


def link_outlines(sim, k: int) -> dict[str, np.ndarray]:
    """Global coordinates of every link's joint points at step ``k`` (frame included)."""
    S = sim.system
    q = sim.sweep.q[k:k + 1]
    out = {}
    for name in S.mech.link_names:
        i = S.index(name)
        pts = [S.point(q, i, S.to_local(name, _joint_point_on(j, name)))[0] for j in S.mech.joints_of(name)
               if j.type != "cam"]  # a cam's contact point moves on both links: drawn apart
        pts += [S.point(q, i, S.to_local(name, p.at))[0] for p in S.mech.points.values() if p.link == name]
        out[name] = np.array(pts)
    return out


def draw_mechanism(ax: Any, sim: Any, k: int, alpha: float = 1.0) -> list:
    """Draw the mechanism of simulation ``sim`` at step ``k`` on ``ax``; returns the artists.

    Moving links are coloured polygons (or bars) through their joint points, the frame's
    pivots triangles, prismatic pairs squares; cam profiles and belt pulleys are drawn too.
    """
    S = sim.system
    arts = []
    outl = link_outlines(sim, k)
    for name, pts in outl.items():
        if name == S.mech.ground:
            arts += ax.plot(pts[:, 0], pts[:, 1], "^", ms=10, color="0.35", alpha=alpha, zorder=3)
            continue
        c = link_colour(sim, name)
        if len(pts) >= 3:
            centre = pts.mean(axis=0)
            order = np.argsort(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]))
            poly = pts[order]
            arts += ax.fill(poly[:, 0], poly[:, 1], color=c, alpha=0.35 * alpha, zorder=2)
            closed = np.vstack([poly, poly[:1]])
            arts += ax.plot(closed[:, 0], closed[:, 1], "-", color=c, lw=2.5, alpha=alpha, zorder=2)
        elif len(pts) == 2:
            arts += ax.plot(pts[:, 0], pts[:, 1], "-", color=c, lw=3, alpha=alpha, zorder=2,
                            solid_capstyle="round")
        arts += ax.plot(pts[:, 0], pts[:, 1], "o", ms=5, mfc="white", mec=c, alpha=alpha, zorder=4)
    for con in S.cons:
        if con.kind != "curve":
            continue
        j = S.mech.joint(con.joint)
        q = sim.sweep.q[k:k + 1]
        prof = j.attrs.get("profile")
        a_name = j.links[0]
        if isinstance(prof, dict) and "points" in prof:
            pts = np.vstack([prof["points"], prof["points"][:1]])
        elif isinstance(prof, dict):
            t = np.linspace(0, 2 * np.pi, 121)
            pts = np.asarray(prof["center"]) + prof["radius"] * np.stack([np.cos(t), np.sin(t)], 1)
        else:
            pts = np.vstack([prof, prof[:1]])
        loc = np.array([S.to_local(a_name, p) for p in pts])
        g = np.array([S.point(q, con.a, p)[0] for p in loc])
        arts += ax.fill(g[:, 0], g[:, 1], color="tab:orange", alpha=0.25 * alpha, zorder=1)
        arts += ax.plot(g[:, 0], g[:, 1], "-", color="tab:orange", lw=1.5, alpha=alpha, zorder=1)
        centre = S.point(q, con.b, con.sb)[0]
        others = [x for x in S.mech.joints_of(j.links[1]) if x.id != j.id and x.type == "R"]
        rho = float(np.linalg.norm(others[0].point - j.point)) if others else 0.0
        if rho > 0:
            t = np.linspace(0, 2 * np.pi, 61)
            arts += ax.plot(centre[0] + rho * np.cos(t), centre[1] + rho * np.sin(t), "-", color="tab:green",
                            lw=1.5, alpha=alpha, zorder=3)
    for con in S.cons:
        if con.kind != "belt":
            continue
        # the pulley, the straight run from the anchor to the tangent point, the wrapped arc
        j = S.mech.joint(con.joint)
        q = sim.sweep.q[k:k + 1]
        centre, anchor = S.point(q, con.b, con.sb)[0], S.point(q, con.a, con.sa)[0]
        t = np.linspace(0, 2 * np.pi, 91)
        arts += ax.plot(centre[0] + con.radius * np.cos(t), centre[1] + con.radius * np.sin(t), "-",
                        color="tab:green", lw=1.5, alpha=alpha, zorder=3)
        try:
            T, _, _ = belt_tangent(centre, anchor, con.radius, j.attrs["wrap"])
        except ValueError:
            continue
        arts += ax.plot([anchor[0], T[0]], [anchor[1], T[1]], "-", color="k", lw=2, alpha=alpha, zorder=3)
        t0 = np.arctan2(T[1] - centre[1], T[0] - centre[0])
        arc = t0 + con.sigma * np.linspace(0, np.pi / 2, 20)
        arts += ax.plot(centre[0] + con.radius * np.cos(arc), centre[1] + con.radius * np.sin(arc), "-",
                        color="k", lw=2, alpha=alpha, zorder=3)
    for j in S.mech.joints:
        if j.type == "P":
            b = j.links[1]
            P = outl[b][[x.id for x in S.mech.joints_of(b)].index(j.id)]
            arts += ax.plot([P[0]], [P[1]], "s", ms=11, mfc="none", mec="0.1", alpha=alpha, zorder=5)
    for xy, rgb in _file_colours(sim, k):  # the file's own colours (e.g. Pyslvs') fill the pins
        arts += ax.plot([xy[0]], [xy[1]], "o", ms=6, mfc=rgb, mec="0.1", mew=0.6, alpha=alpha, zorder=6)
    return arts


def _file_colours(sim: Any, k: int) -> list[tuple[np.ndarray, tuple[float, float, float]]]:
    """(position at step ``k``, RGB) of each joint and point the file's ``colors`` names."""
    S = sim.system
    colours = S.mech.attrs.get("colors") or {}
    q = sim.sweep.q[k:k + 1]
    out = []
    for key, colour in colours.items():
        rgb = color_rgb(colour)
        if rgb is None:
            continue
        if key in S.mech.points:
            link, at = S.mech.points[key].link, S.mech.points[key].at
        else:
            j = next((j for j in S.mech.joints if j.id == key and j.point is not None), None)
            if j is None:
                continue
            link, at = j.links[1], _joint_point_on(j, j.links[1])
        out.append((S.point(q, S.index(link), S.to_local(link, at))[0], rgb))
    return out


def link_colour(sim: Any, link: str) -> Any:
    """The colour of ``link`` in every figure: Matplotlib's tab10 by the link's place in the file."""
    names = list(sim.system.mech.link_names) if sim.system is not None else list(sim.links)
    return matplotlib.colormaps["tab10"](names.index(link) % 10 if link in names else 7)


def _point_styles(sim: Any) -> dict[str, tuple[Any, str]]:
    """Colour (its link's) and line style (solid, then dashed, ... for more points on one link)."""
    seen: dict[str, int] = {}
    out = {}
    for name, pm in sim.points.items():
        n = seen.get(pm.link, 0)
        seen[pm.link] = n + 1
        out[name] = (link_colour(sim, pm.link), ("-", "--", ":", "-.")[n % 4])
    return out


def _input_axis(sim) -> tuple[np.ndarray, str]:
    main = sim.main_input
    unit = "deg" if sim.input_types[main] == "R" else "length"
    return sim.inputs[main], f"input {main} ({unit})"


def plot_paths(sim: Any, ax: Any = None) -> Any:
    """The mechanism at its first assembled input and the paths of its named points.

    Parameters
    ----------
    sim : Simulation
        From :func:`mechsyn.simulate`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure's Axes when omitted.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = axes(ax, (6.4, 5.6))
    k0 = int(np.argmax(sim.assembled)) if sim.assembled.any() else None
    if k0 is not None:
        draw_mechanism(ax, sim, k0)
    styles = _point_styles(sim)
    for name, pm in sim.points.items():
        c, ls = styles[name]
        ax.plot(pm.position[:, 0], pm.position[:, 1], ls, color=c, lw=1.5, label=f"path of {name}")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"x ({_length_unit(sim)})")
    ax.set_ylabel(f"y ({_length_unit(sim)})")
    ax.set_title("mechanism (first assembled input) and point paths")
    ax.grid(alpha=0.3)
    if sim.points:
        ax.legend(fontsize=8, loc="best")
    return ax


def assembled_rows(sim: Any, what: str) -> np.ndarray:
    """The rows of ``sim`` where the mechanism is assembled; a
    :class:`~mechsyn.errors.MechsynInputError` when there is none (nothing to ``what``)."""
    idx = np.flatnonzero(sim.assembled)
    if len(idx) == 0:
        raise MechsynInputError(f"nothing to {what}: the mechanism is not assembled at any input",
                                hint="widen the input range, or start it inside the working range")
    return idx


def plot_simulation(sim: Any, fig: Any = None, title: str | None = None) -> Any:
    """Four panels: mechanism and point paths; point speeds; point accelerations; link
    angular velocities, over the input. Returns the Figure; a
    :class:`~mechsyn.errors.MechsynInputError` when no input is assembled."""
    assembled_rows(sim, "plot")
    x, xlabel = _input_axis(sim)
    fig = figure(fig, (12, 9))
    axs = fig.subplots(2, 2)
    plot_paths(sim, axs[0, 0])
    unit = _length_unit(sim)
    styles = _point_styles(sim)
    for ax, key, lab in ((axs[0, 1], "velocity", f"speed |v| ({unit}/s)"),
                         (axs[1, 0], "acceleration", f"acceleration |a| ({unit}/s²)")):
        for name, pm in sim.points.items():
            c, ls = styles[name]
            ax.plot(x, np.linalg.norm(getattr(pm, key), axis=1), ls, color=c, label=name)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        if sim.points:
            ax.legend(fontsize=8)
        ax.set_title(f"point {key}")
    ax = axs[1, 1]
    for name, lm in sim.links.items():
        ax.plot(x, lm.angular_velocity, color=link_colour(sim, name), label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("angular velocity (rad/s)")
    ax.set_title("link angular velocities")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    for e in sim.events:
        if e["kind"] == "dead point" and isinstance(e.get("input"), dict):
            v = e["input"].get(sim.main_input)
            for a in (axs[0, 1], axs[1, 0], axs[1, 1]):
                a.axvline(v, color="red", ls=":", lw=1)
    fig.suptitle(title or f"{sim.mechanism}: kinematics ({sim.method})")
    fig.tight_layout()
    return fig


def plot_forces(fa: Any, fig: Any = None, title: str | None = None) -> Any:
    """Reaction magnitudes in every joint and the balancing efforts, over the input.
    Returns the Figure; a :class:`~mechsyn.errors.MechsynInputError` when no input is assembled."""
    sim = fa.simulation
    assembled_rows(sim, "plot")
    x, xlabel = _input_axis(sim)
    fig = figure(fig, (13, 5))
    axs = fig.subplots(1, 2)
    for j, F in fa.reactions.force.items():
        axs[0].plot(x, np.linalg.norm(F, axis=1), label=j)
    axs[0].set_title("joint reactions |F|")
    axs[0].set_xlabel(xlabel)
    unit = _length_unit(sim)
    axs[0].set_ylabel(f"force (mass·{unit}/s²)")
    axs[0].grid(alpha=0.3)
    axs[0].legend(fontsize=8, ncol=2)
    for j, e in fa.reactions.effort.items():
        axs[1].plot(x, e, label=f"{j} ({fa.reactions.effort_kind[j]})")
    axs[1].axhline(0, color="0.5", lw=0.8)
    axs[1].set_title("balancing moment / force at the driven joints")
    axs[1].set_xlabel(xlabel)
    kinds = set(fa.reactions.effort_kind.values())
    axs[1].set_ylabel(" or ".join(f"{k} (force·{unit})" if k == "moment" else f"{k}" for k in sorted(kinds))
                      or "effort")
    axs[1].grid(alpha=0.3)
    axs[1].legend(fontsize=8)
    kind = "static" if fa.static else "kinetostatic"
    g = np.asarray(fa.gravity, float) + 0.0  # + 0.0: no "-0.0" in the title
    gravity = f"gravity ({g[0]:g}, {g[1]:g})" if np.any(g) else "no gravity"
    fig.suptitle(title or f"{sim.mechanism}: {kind} analysis, {gravity}")
    fig.tight_layout()
    return fig


def _length_unit(sim: Any) -> str:
    """The length unit of the mechanism file (``units:``), else "length"."""
    return sim.system.mech.attrs.get("units") or "length"


def _redraw_animation(sim: Any, fig: Any, ax: Any, frames: np.ndarray, x: np.ndarray, xlabel: str,
                      interval: float) -> Any:
    """An animation redrawn whole at each frame (cams and belts change shape as they move)."""
    from mechsyn.plot.animation import MechanismAnimation

    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    unit = _length_unit(sim)

    styles = _point_styles(sim)

    def draw(k):
        ax.clear()
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.set_xlabel(f"x ({unit})")
        ax.set_ylabel(f"y ({unit})")
        for name, pm in sim.points.items():
            ax.plot(pm.position[:, 0], pm.position[:, 1], "-", lw=1, color="0.7")
            ax.plot(pm.position[:k + 1, 0], pm.position[:k + 1, 1], styles[name][1], color=styles[name][0],
                    lw=1.8, label=name)
            ax.plot([pm.position[k, 0]], [pm.position[k, 1]], "o", ms=4, color="k")
        arts = draw_mechanism(ax, sim, k)
        ax.set_title(f"{sim.mechanism}\n{xlabel.split(' (')[0]} = {x[k]:.4g}", fontsize=10)
        if sim.points:
            ax.legend(fontsize=8, loc="upper right")
        return arts

    return MechanismAnimation(fig, draw, frames=list(frames), blit=False, interval=interval, title=sim.mechanism)


def _bare_figure() -> Any:
    """A Matplotlib Figure outside pyplot (a notebook shows the animation's player, not a
    still frame of it)."""
    from matplotlib.figure import Figure

    return Figure()


def _animation_view(ax: Any, sim: Any, frames: np.ndarray, idx: np.ndarray) -> None:
    """Fix the animation's view: everything drawn at a dozen frames, with the point paths,
    then cleared, the limits kept (padded), equal aspect, labelled axes."""
    for k in frames[:: max(1, len(frames) // 12)]:
        draw_mechanism(ax, sim, k)
    for pm in sim.points.values():
        ax.plot(pm.position[idx, 0], pm.position[idx, 1])
    ax.relim()
    lo = np.array([ax.dataLim.x0, ax.dataLim.y0])
    hi = np.array([ax.dataLim.x1, ax.dataLim.y1])
    pad = 0.08 * max(hi - lo) + 1e-9
    ax.clear()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel(f"x ({_length_unit(sim)})")
    ax.set_ylabel(f"y ({_length_unit(sim)})")


def animate_simulation(sim: Any, fig: Any = None, max_frames: int = 90, interval: float = 1000 / 15,
                       bare: bool = False) -> Any:
    """The mechanism moving over the assembled inputs, tracing its points' paths.

    ``bare``: without ``fig``, a bare Figure (no pyplot: a notebook shows the player).

    Returns a :class:`~mechsyn.plot.animation.MechanismAnimation`, a ``FuncAnimation`` that
    plays when it is a notebook cell's value and saves with ``anim.save("m.gif")`` (or
    ``.mp4``, ``.html``), drawing only what moves.
    Raises :class:`~mechsyn.errors.MechsynInputError` when no input is assembled.
    """
    from mechsyn.plot.animation import MechanismAnimation

    idx = assembled_rows(sim, "animate")
    frames = idx[np.unique(np.linspace(0, len(idx) - 1, min(max_frames, len(idx))).astype(int))]
    fig = figure(_bare_figure() if fig is None and bare else fig, (6.4, 5.6))
    ax = fig.add_subplot()
    _animation_view(ax, sim, frames, idx)
    x, xlabel = _input_axis(sim)
    if any(c.kind in ("curve", "belt") for c in sim.system.cons):
        return _redraw_animation(sim, fig, ax, frames, x, xlabel, interval)
    # the artists are made once and moved at each frame (no clearing, no re-layout)
    S = sim.system
    trails = []
    styles = _point_styles(sim)
    for name, pm in sim.points.items():
        ax.plot(pm.position[idx, 0], pm.position[idx, 1], "-", lw=1, color="0.7")
        trail, = ax.plot([], [], styles[name][1], color=styles[name][0], lw=1.8, label=name)
        dot, = ax.plot([], [], "o", ms=4, color="k")
        trails.append((pm.position, trail, dot))
    links = []
    for name in S.mech.link_names:
        c = link_colour(sim, name)
        if name == S.mech.ground:
            links.append((name, None, ax.plot([], [], "^", ms=10, color="0.35", zorder=3)[0], None))
            continue
        fill = ax.fill([0, 0], [0, 0], color=c, alpha=0.35, zorder=2)[0]
        edge, = ax.plot([], [], "-", color=c, lw=2.5, zorder=2, solid_capstyle="round")
        pins, = ax.plot([], [], "o", ms=5, mfc="white", mec=c, zorder=4)
        links.append((name, fill, edge, pins))
    sliders = [(j.links[1], [x.id for x in S.mech.joints_of(j.links[1])].index(j.id))
               for j in S.mech.joints if j.type == "P"]
    squares, = ax.plot([], [], "s", ms=11, mfc="none", mec="0.1", zorder=5)
    # the file's own colours (``colors:``) fill the pins, as in the static figure
    file_pins = [ax.plot([], [], "o", ms=6, mfc=rgb, mec="0.1", mew=0.6, zorder=6)[0]
                 for _, rgb in _file_colours(sim, frames[0])]
    title = ax.set_title("", fontsize=10)
    if sim.points:
        ax.legend(fontsize=8, loc="upper right")

    def draw(k):
        for pos, trail, dot in trails:
            trail.set_data(pos[:k + 1, 0], pos[:k + 1, 1])
            dot.set_data([pos[k, 0]], [pos[k, 1]])
        outl = link_outlines(sim, k)
        for name, fill, edge, pins in links:
            pts = outl[name]
            if fill is None:
                edge.set_data(pts[:, 0], pts[:, 1])
                continue
            if len(pts) >= 3:
                centre = pts.mean(axis=0)
                poly = pts[np.argsort(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]))]
                fill.set_xy(poly)
                fill.set_visible(True)
                closed = np.vstack([poly, poly[:1]])
                edge.set_data(closed[:, 0], closed[:, 1])
                edge.set_linewidth(2.5)
            else:
                fill.set_visible(False)
                edge.set_data(pts[:, 0], pts[:, 1])
                edge.set_linewidth(3)
            pins.set_data(pts[:, 0], pts[:, 1])
        if sliders:
            sq = np.array([outl[b][i] for b, i in sliders])
            squares.set_data(sq[:, 0], sq[:, 1])
        for pin, (xy, _) in zip(file_pins, _file_colours(sim, k)):
            pin.set_data([xy[0]], [xy[1]])
        title.set_text(f"{sim.mechanism}\n{xlabel.split(' (')[0]} = {x[k]:.4g}")
        return ([a for _, trail, dot in trails for a in (trail, dot)]
                + [a for _, f, e, p in links for a in (f, e, p) if a is not None] + file_pins + [squares, title])

    anim = MechanismAnimation(fig, draw, frames=list(frames), blit=False, interval=interval, title=sim.mechanism)
    anim.mechsyn_blit = (draw, list(frames))  # what moves: see mechsyn.plot.frames
    return anim
