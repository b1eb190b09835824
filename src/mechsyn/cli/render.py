"""Rich rendering of the library's reports for the terminal: one function per report.

The commands parse options, make one library call and hand its report to a function here;
``--json`` prints the report's ``to_dict()`` instead.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from rich.markup import escape
from rich.panel import Panel

from mechsyn.cli.common import Table, console, fmt_number, safe

if TYPE_CHECKING:
    from mechsyn.structure.analysis import StructuralAnalysis
    from mechsyn.structure.compare import Comparison, RemedyCheck
    from mechsyn.structure.rank import RankAnalysis
    from mechsyn.structure.remedies import Remedy
    from mechsyn.structure.report import StructureReport


def table_rows(n: int, max_rows: int = 25) -> list[int]:
    """Indices of at most ``max_rows`` evenly spaced rows of ``n``."""
    if n <= max_rows:
        return list(range(n))
    return sorted(set(np.linspace(0, n - 1, max_rows).astype(int).tolist()))


def say_rows_shown(shown: int, total: int) -> None:
    """Say when the tables show a subset of the positions, and how to see them all."""
    if shown < total:
        console.print(f"(tables show {shown} of {total} positions, evenly spaced; all of them with --json "
                      "or --csv FILE)", highlight=False)


def _events(sim: Any) -> None:
    for e in sim.events:
        where = ", ".join(f"{k} = {v:.6g}" for k, v in e.input.items()) if isinstance(e.input, dict) else ""
        console.print(f"[yellow]{e.kind}[/] {where}: {escape(e.message)}", highlight=False)


def _point_tables(sim: Any, rows: list[int], head: str) -> None:
    x = sim.inputs[sim.main_input]
    for name, pm in sim.points.items():
        values = [(*pm.position[k], *pm.velocity[k], *pm.acceleration[k]) if sim.assembled[k] else None
                  for k in rows]
        heads = (head, "x", "y", "vx", "vy", "ax", "ay")
        t = Table(title=f"point {name} (on {pm.link})")
        for col in heads:
            t.add_column(col, justify="right", no_wrap=True, overflow="ellipsis")
        for row in _fitting_cells(values, [f"{x[k]:g}" for k in rows], heads, console.width):
            t.add_row(*row)
        console.print(t)


def _fitting_cells(values: list, first: list[str], heads: tuple, width: int) -> list[list[str]]:
    """Table rows of numbers (``None``: a position not assembled) with the most significant
    digits (6 down to 3) for which the table, with its column ``heads``, fits ``width``
    columns (a rich table takes 3 characters per column and 1 more): a number is never
    split over two lines."""
    blank = ["not assembled"] + [""] * (len(heads) - 2)
    for digits in (6, 5, 4, 3):
        cells = [[f0, *(blank if row is None else (fmt_number(v, f".{digits}g") for v in row))]
                 for f0, row in zip(first, values)]
        if _table_width(cells, heads) <= width:
            break
    return cells


def _table_width(cells: list[list[str]], heads: tuple) -> int:
    """Columns a rich table of ``cells`` under ``heads`` takes (3 per column and 1 more)."""
    return 1 + sum(max([len(h)] + [len(r[i]) for r in cells]) + 3 for i, h in enumerate(heads))


def _link_table(sim: Any, rows: list[int], head: str, most: int = 4) -> None:
    """The links' angle θ, angular velocity ω and acceleration α, each in a column of its own,
    as many links to a table as fit the console's width (up to ``most`` links shown)."""
    x = sim.inputs[sim.main_input]
    names = list(sim.links)[:most]
    first = [f"{x[k]:g}" for k in rows]

    def cells(group: list[str]) -> tuple[list[list[str]], tuple]:
        heads = (head, *(f"{n} {q}" for n in group for q in ("θ", "ω", "α")))
        values = [None if not sim.assembled[k] else
                  [v for n in group for v in (sim.links[n].angle[k], sim.links[n].angular_velocity[k],
                                              sim.links[n].angular_acceleration[k])] for k in rows]
        return _fitting_cells(values, first, heads, console.width), heads

    title = "links: angle θ (deg), angular velocity ω (rad/s), acceleration α (rad/s²)"
    while names:
        size = len(names)
        while size > 1 and _table_width(*cells(names[:size])) > console.width:
            size -= 1
        body, heads = cells(names[:size])
        t = Table(title=title)
        for col in heads:
            t.add_column(col, justify="right", no_wrap=True, overflow="ellipsis")
        for row in body:
            t.add_row(*row)
        console.print(t)
        names, title = names[size:], None
    if len(sim.links) > most:
        console.print(f"({len(sim.links) - most} more links in --json / --csv)", highlight=False)


def _derived_lines(d: dict[str, Any]) -> None:
    if "grashof" in d:
        console.print(f"Grashof: {d['grashof']['expression']} → {d['grashof']['classification']}", highlight=False)
    for k, v in d.get("transmission_angle", {}).items():
        console.print(f"transmission angle of dyad {k}: {fmt_number(v['min'])} .. {fmt_number(v['max'])} deg",
                      highlight=False)
    for name, e in d.get("extent", {}).items():
        if e["width"] is not None:
            size = max(abs(e[k]) for k in ("x_min", "x_max", "y_min", "y_max"))  # noise: below 1e-12 of it
            x0, x1, y0, y1, w, h = (fmt_number(e[k], scale=size) for k in ("x_min", "x_max", "y_min", "y_max",
                                                                          "width", "height"))
            console.print(f"path of {name}: x {x0} .. {x1}, y {y0} .. {y1} (width {w}, height {h})", highlight=False)
    _motion_lines(d.get("motion") or {})
    for name, s in d.get("straightness", {}).items():
        console.print(f"straightness of {name} over {s['range'][0]:g}..{s['range'][1]:g}: largest deviation "
                      f"{s['max_deviation']:.6g} over a length {s['length']:.6g}", highlight=False)


def _motion_lines(m: dict[str, Any]) -> None:
    """The sliders' strokes, the rockers' ranges and the time ratios (``derived["motion"]``)."""
    def ratio(t: Any) -> str:
        return "" if not t else (f"; time ratio {t['ratio']:.4g} (working stroke {t['forward']:.4g} deg of the "
                                 f"crank, return {t['return']:.4g} deg)")

    for jid, s in m.get("sliders", {}).items():
        lo, hi = s["min"], s["max"]
        console.print(f"slider {jid} on {s['guide']}: stroke {s['stroke']:.6g} (slide {lo['slide']:.6g} at input "
                      f"{lo['input']:.4g} .. {hi['slide']:.6g} at {hi['input']:.4g}){ratio(s['time_ratio'])}",
                      highlight=False)
    for link, r in m.get("rockers", {}).items():
        if r["full_turn"]:
            console.print(f"link {link} (pivot {r['pivot']}): turns fully", highlight=False)
        else:
            console.print(f"link {link} rocks on {r['pivot']}: range {r['range']:.4g} deg ({r['min']['angle']:.4g} at "
                          f"input {r['min']['input']:.4g} .. {r['max']['angle']:.4g} at {r['max']['input']:.4g})"
                          f"{ratio(r['time_ratio'])}", highlight=False)


def render_simulation(report: Any) -> None:
    """``mechsyn simulate``: point and link tables, working ranges, events, derived quantities."""
    sim = report.simulation
    main = sim.main_input
    x = sim.inputs[main]
    unit = "deg" if sim.input_types[main] == "R" else ""
    head = f"{main} {unit}".strip()
    rows = table_rows(len(x))
    console.print(f"[bold]{escape(sim.mechanism)}[/]: {len(x)} input values, {int(sim.assembled.sum())} assembled "
                  f"(method: {sim.method})", highlight=False)
    _point_tables(sim, rows, head)
    _link_table(sim, rows, head)
    say_rows_shown(len(rows), len(x))
    for r in sim.working_ranges():
        console.print(f"working range of {main}: {r[0]:g} .. {r[1]:g} {unit}", highlight=False)
    _events(sim)
    for note in sim.notes:
        console.print(f"note: {escape(note)}", highlight=False)
    _derived_lines(report.derived)


def _effort_table(fa: Any, rows: list[int]) -> None:
    sim, R = fa.simulation, fa.reactions
    x = sim.inputs[sim.main_input]
    per_input = list(R.force) if len(R.force) <= 5 else []
    t = Table(title="balancing efforts at the drives" + (" and reactions |F| (on each joint's second link)"
                                                         if per_input else ""))
    t.add_column(sim.main_input, justify="right")
    for j in R.effort:
        t.add_column(f"{R.effort_kind[j]} at {j}", justify="right")
    for j in per_input:
        t.add_column(f"|F_{j}|", justify="right")
    for k in rows:
        row = [f"{x[k]:g}"] + [fmt_number(float(e[k])) for e in R.effort.values()]
        row += [fmt_number(float(np.linalg.norm(R.force[j][k]))) for j in per_input]
        t.add_row(*row)
    console.print(t)


def _reaction_table(fa: Any) -> None:
    sim, R = fa.simulation, fa.reactions
    x = sim.inputs[sim.main_input]
    mech_joints = {j.id: j for j in sim.system.mech.joints}
    t = Table(title="joint reactions over the sweep (force of the first link on the second)")
    for col in ("joint", "links", "max |F|", f"at {sim.main_input}", "min |F|", "max |M|"):
        t.add_column(col, justify="left" if col in ("joint", "links") else "right")
    for j in R.force:
        mag = np.linalg.norm(R.force[j], axis=1)
        if not np.isfinite(mag).any():
            t.add_row(j, " - ".join(mech_joints[j].links), "—", "—", "—", "—")
            continue
        k = int(np.nanargmax(mag))
        t.add_row(j, " → ".join(mech_joints[j].links), fmt_number(float(mag[k])), f"{x[k]:g}",
                  fmt_number(float(np.nanmin(mag))), fmt_number(float(np.nanmax(np.abs(R.moment[j])))))
    console.print(t)


def render_forces(fa: Any) -> None:
    """``mechsyn forces``: balancing efforts, reactions, notes and events."""
    sim = fa.simulation
    x = sim.inputs[sim.main_input]
    rows = table_rows(len(x))
    kind = "static" if fa.static else "kinetostatic"
    console.print(f"[bold]{escape(sim.mechanism)}[/]: {kind} analysis, gravity {0.0 - fa.gravity[1]:g} along -y, "
                  f"{int(sim.assembled.sum())} of {len(x)} inputs assembled", highlight=False)
    _effort_table(fa, rows)
    say_rows_shown(len(rows), len(x))
    _reaction_table(fa)
    if fa.reactions.indeterminate:
        console.print("[yellow]note:[/] redundant constraints: the reactions are statically indeterminate; "
                      "minimum-norm values shown", highlight=False)
    for note in fa.notes():
        console.print(f"[yellow]note:[/] {escape(note)}", highlight=False)
    _events(sim)


def render_atlas(atlas: Any, include_degenerate: bool = False) -> None:
    """``mechsyn atlas``: one row per link assortment, then each chain's joints (up to 40)."""
    by_input = atlas.mechanisms_by != "frame"
    table = Table(title=f"{atlas.n_links} links, mobility {atlas.mobility}, "
                  f"{atlas.n_joints} joints: {atlas.count} chains")
    for col in ("assortment", "chains", "non-planar", "fractionated",
                "mechanisms" + (" (frame, input)" if by_input else " (frames)")):
        table.add_column(col, justify="right" if col != "assortment" else "left")
    if include_degenerate:
        table.add_column("degenerate", justify="right")
    realised = [row for row in atlas.assortments if row["chains"] or row["degenerate"]]
    empty = [row["label"] for row in atlas.assortments if row not in realised]
    for row in realised:
        cells = [row["label"], *(str(row[k]) for k in ("chains", "non_planar", "fractionated", "mechanisms"))]
        table.add_row(*cells, *([str(row["degenerate"])] if include_degenerate else []))
    console.print(table)
    if empty:
        console.print("assortments without a non-degenerate chain: " + ", ".join(empty), highlight=False)
    if len(atlas.kinematic_chains) <= 40:
        for rec, chain in zip(atlas.chains, atlas.kinematic_chains):
            console.print(f"#{rec['number']} {chain.assortment_label()}: joints "
                          + " ".join(f"{a}-{b}" for a, b in chain.edges), highlight=False)


def _transmission_line(res: Any) -> str:
    mu = res.worst_transmission_angle_deg
    text = (f"worst transmission angle over the motion: {mu:.2f} deg"
            + (f" (limit {res.transmission_angle_min_deg:g})" if res.transmission_angle_min_deg else ""))
    if res.fold_distance_deg is not None:
        text += f"\nnearest approach to folding flat: {res.fold_distance_deg:.2f} deg"
        text += f" (limit {res.fold_margin_deg:g})" if res.fold_margin_deg else ""
    return text


def render_path_synthesis(case: Any, res: Any) -> None:
    """``mechsyn synth path``: the design, its error against the published best, feasibility."""
    t = Table(title=f"Path synthesis {case.id}" + (" (interrupted: best so far)" if res.interrupted else ""))
    t.add_column("variable")
    t.add_column("value", justify="right")
    for k, v in res.design.items():
        t.add_row(k, f"{v:.8g}")
    console.print(t)
    console.print(f"error (sum of squared distances): [bold]{res.error:.8g}[/]"
                  + (f"   published best: {case.best_known:.8g}" if case.best_known else ""))
    console.print(f"feasible: {res.feasible}   assembled at all targets: {res.assembled_at_all_targets}   "
                  f"branch {case.branch}   {res.restarts} restart{'s' if res.restarts != 1 else ''}, {res.seconds:.1f} s"
                  + ("   (target error reached)" if res.target_reached else ""))
    if res.size_ratio is not None:
        console.print(f"size: {res.size_ratio:.4g} target diagonals about the targets' centroid"
                      + (f" (bound {res.max_size:g})" if res.max_size else " (no size bound)"), highlight=False)
    if res.reason:   # why it is infeasible, or the bound that decides it and how to lift it
        console.print(f"[bold yellow]{escape(res.reason)}[/]", highlight=False)
    console.print(_transmission_line(res))


def render_motion(report: Any) -> None:
    """``mechsyn synth motion``: the best linkages, their pivots, lengths, defects and errors."""
    t = Table(title=f"Burmester motion generation, {len(report.poses)} poses ({report.verified_count} of "
              f"{report.count} verified)")
    for c in ("O2", "O4", "r1", "r2", "r3", "r4", "type", "min mu [deg]", "defects", "pos. error"):
        t.add_column(c, justify="right")
    for s in report.solutions:
        defects = ", ".join(k for k, v in (("branch", s.branch_defect), ("order", s.order_defect)) if v) or "none"
        t.add_row(f"({s.O2[0]:.4g}, {s.O2[1]:.4g})", f"({s.O4[0]:.4g}, {s.O4[1]:.4g})", f"{s.r1:.4g}", f"{s.r2:.4g}",
                  f"{s.r3:.4g}", f"{s.r4:.4g}", s.grashof, f"{s.min_transmission_deg:.1f}", defects,
                  f"{s.position_error:.2e}")
    console.print(t)


def render_mechanism_synthesis(case: Any, res: Any) -> None:
    """``mechsyn synth mechanism``: start and final design, errors, feasibility."""
    t = Table(title=f"{case.problem.capitalize()} synthesis: {case.name}"
              + (" (interrupted: best so far)" if res.interrupted else ""))
    t.add_column("variable")
    t.add_column("start", justify="right")
    t.add_column("design", justify="right")
    for k, v in res.design.items():
        t.add_row(k, f"{res.start_design[k]:.6g}", f"{v:.8g}")
    console.print(t)
    se = "infeasible" if res.start_error is None else f"{res.start_error:.6g}"
    console.print(f"error ({'sum of squared distances' if case.problem == 'path' else 'pose error'}): "
                  f"[bold]{res.error:.8g}[/]   (start design: {se})")
    console.print(f"feasible: {res.feasible}   evaluation: {res.method}   {res.restarts} restarts, "
                  f"{res.nfev} evaluations, {res.seconds:.1f} s"
                  + ("   (time limit reached)" if res.stopped_by_time_limit else ""))
    if not res.feasible:
        console.print(f"[bold red]no feasible design found[/]: {res.reason}")


def render_curve_synthesis(res: Any) -> None:
    """``mechsyn synth curve``: the ranked candidates (the simplest within the tolerance
    and the most accurate labelled), their errors, where each departs most, the notes."""
    tgt = res.target
    t = Table(title=f"Curve synthesis: {tgt.source} ({'closed' if tgt.closed else 'open'}, {len(tgt.points)} points)")
    for c in ("#", "topology", "error", "", "size", "mu", "ratio", "input"):
        t.add_column(c, justify="right" if c not in ("topology", "") else "left", no_wrap=c != "",
                     min_width=12 if c == "topology" else None)
    short = {"simplest within tolerance": "simplest", "most accurate": "most accurate",
             "simplest within tolerance and most accurate": "simplest, most accurate"}
    for i, c in enumerate(res.candidates, 1):
        d = c.to_dict()
        inp = d["input"]
        turn = "full turn" if c.full_turn else f"{inp['start']:.0f}..{inp['stop']:.0f}°"
        role = short.get(c.role, "") + ("" if c.refined else (", " if c.role else "") + "not refined")
        t.add_row(str(i), d["topology"], f"{100 * c.chamfer:.2f} %", role,
                  f"{c.size_ratio:.2f}", f"{c.min_transmission_angle:.0f}°",
                  f"{c.link_length_ratio:.1f}", turn)
    if res.candidates:
        console.print(t)
    for i, c in enumerate(res.candidates, 1):
        if 0 <= c.departs_at < len(tgt.points):
            x, y = tgt.points[c.departs_at]
            console.print(f"{i}: departs most at points[{c.departs_at}] ({x:.4g}, {y:.4g}), "
                          f"{100 * c.departure:.2f} % of the diagonal away", highlight=False)
    limit = f" of {res.time_limit:g} s" if getattr(res, "time_limit", None) else ""
    console.print(f"error: symmetric chamfer along both curves in order (target and path, each point to the "
                  f"other curve where the order puts it, mean over arc length) / the target's diagonal ({tgt.diagonal:.4g}, along its principal axes); size: "
                  f"radius about the target's centroid, in diagonals; {res.refined} refinements of "
                  f"{res.retrieved} retrieved designs in {res.seconds:.1f} s{limit}; {_checked(res.candidates)}"
                  + ("; interrupted: best so far" if res.interrupted else ""),
                  highlight=False)
    for n in res.notes:
        console.print(f"note: {n}", highlight=False)


def _checked(candidates) -> str:
    """What the closing line says of the candidates' check by ``simulate`` (a short time limit
    can answer before the check has run)."""
    n = sum(bool(c.verified) for c in candidates)
    return ("every candidate re-simulated by simulate" if n == len(candidates)
            else f"{n} of {len(candidates)} candidates re-simulated by simulate")


#: Arms with more joints than this get their joint values below the table, wrapped to the
#: terminal, instead of one column per joint (a 100-joint arm's table was 2,000 columns wide).
JOINT_COLUMNS_MAX = 6


def _configuration_table(arm: Any, res: Any) -> tuple[Any, list[int], list[tuple[str, Any]]]:
    """The table of configurations (the best 12 of many), the indices shown, and the rows'
    labels with their configurations (the joint values listed below a long arm's table)."""
    from rich import box

    from mechsyn.capability.measures import MEASURES

    configs, wide = res.configurations, arm.n <= JOINT_COLUMNS_MAX
    table = Table(box=box.SIMPLE_HEAD, pad_edge=False, title=f"{arm.name}: speed along "
                  f"({', '.join(f'{c:g}' for c in np.round(res.direction, 4))}) at ({', '.join(f'{c:g}' for c in res.point)})")
    table.add_column("" if wide else "config")
    for name in arm.joint_names if wide else ():
        table.add_column(name, justify="right", no_wrap=True, min_width=6)
    for head in ("exact", "compon.", "min-nrm", "st.mn", "stepped"):
        table.add_column(head, justify="right", no_wrap=True)
    shown = list(range(len(configs)))
    if len(configs) > 15:  # many IK solutions (spatial arms): the best ones
        shown = sorted(np.argsort([-c[res.measure] for c in configs], kind="stable")[:12].tolist())
    # (name, tag, configuration): a long arm's rows are named by number, the wide table's by tag only
    rows = [(f"{k + 1}", "best" if k == res.best_index else "", configs[k]) for k in shown]
    if res.continuous_best:
        rows.append(("cont", "cont", res.continuous_best))
    styles = {"best": "bold green", "cont": "cyan", "": None}
    for name, tag, c in rows:
        label = tag if wide else (f"{name} best" if tag == "best" else name)
        joints = [f"{v:.1f}" for v in c["q_deg"]] if wide else []
        table.add_row(label, *joints, *[f"{c[mn]:.2f}" for mn in MEASURES], style=styles[tag])
    return table, shown, [] if wide else [(name, c) for name, _, c in rows]


def render_point_capability(arm: Any, res: Any, step: float) -> None:
    """``mechsyn capability --point``: every configuration's joints and measures, the best marked
    (a long arm's joint values listed below the table, wrapped to the terminal)."""
    from mechsyn.capability.point import MEASURE_HELP

    measure, configs, cb = res.measure, res.configurations, res.continuous_best
    from mechsyn.cli.common import SafeConsole

    table, shown, listed = _configuration_table(arm, res)
    need = 12 + 8 * arm.n + 50 if not listed else 0
    (console if console.is_terminal or console.width >= need else SafeConsole(width=need)).print(table)
    unit = "deg" if arm.is_revolute.all() else "deg; prismatic joints: length"
    for label, c in listed:
        console.print(f"{label}: q ({unit}) = " + ", ".join(f"{v:.1f}" for v in c["q_deg"]), highlight=False)
    if len(shown) < len(configs):
        console.print(f"showing the best {len(shown)} of {len(configs)} configurations (all with --json)")
    if not configs:
        console.print("[yellow]no allowed configuration reaches this point[/]")
    else:
        console.print(f"best sampled ({measure}): {configs[res.best_index][measure]:.3f}"
                      + (f"; continuous search over the self-motion (cont): {cb[measure]:.3f}" if cb else ""))
    for r in res.rejected:
        console.print(f"rejected q = ({', '.join(f'{v:.2f}' for v in r['q_deg'])}): {r['reason']}")
    console.print("[dim]exact: " + MEASURE_HELP["exact"] + "; compon.: " + MEASURE_HELP["component"]
                  + "; min-nrm: " + MEASURE_HELP["min_norm"] + "; st.mn / stepped: the paper's "
                  f"{step:g}-step raise with minimum-norm rates / with the null space in full[/]")


def render_capability_map(cmap: Any) -> None:
    """``mechsyn capability --grid``: the map as a table (up to 144 points), its range, the
    interpolated configuration."""
    xs, ys, measure = cmap.xs, cmap.ys, cmap.measure
    v = np.where(np.isfinite(cmap.value), cmap.value, np.nan)
    total = xs.size * ys.size
    if total <= 144:
        table = Table(title=f"V_max ({measure}, {cmap.search}); rows x, columns y")
        table.add_column("x \\ y")
        for y in ys:
            table.add_column(f"{y:g}", justify="right")
        for i, x in enumerate(xs):
            table.add_row(f"{x:g}", *["?" if not ok else "-" if not np.isfinite(c) else f"{c:.2f}"
                                      for c, ok in zip(v[i], cmap.done()[i])])
        console.print(table)
    if np.isfinite(v).any():
        i, j = np.unravel_index(np.nanargmax(v), v.shape)
        console.print(f"{total} points, {int(np.isfinite(v).sum())} reachable; V_max from "
                      f"{np.nanmin(v):.3f} to {np.nanmax(v):.3f} (at x={xs[i]:g}, y={ys[j]:g})")
    else:
        console.print(f"{total} points, none reachable with the allowed configurations")
    interp = cmap.interpolated
    if interp is not None:
        at = interp["point"]
        if interp["q_deg"] is None:
            console.print("interpolation: no optimal configuration near this point")
        else:
            console.print(f"interpolated optimal configuration at ({at[0]:g}, {at[1]:g}) "
                          f"({interp['method']}): q = ({', '.join(f'{c:.3f}' for c in interp['q_deg'])})"
                          f"; tool {interp['tool_error']:.3g} from the point (correct with IK); "
                          f"{measure} {interp[measure]:.3f}")


def render_plates(layout: Any) -> None:
    """``mechsyn export``: one row per plate (its holes and size), then the layout's notes."""
    from mechsyn.cli.common import err_console

    t = Table(title=f"{escape(layout.mechanism)}: {len(layout.plates)} plates, width {layout.width:.4g}, "
                    f"holes {layout.cut_diameter:.4g} (pin {layout.hole_diameter:.4g} + {layout.clearance:.4g})")
    for col in ("link", "holes", "size"):
        t.add_column(col)
    for p in layout.plates:
        t.add_row(escape(p.link), escape(", ".join(p.hole_names)), f"{p.size[0]:.4g} x {p.size[1]:.4g}")
    console.print(t)
    for note in layout.notes:
        err_console.print(f"note: {escape(note)}", highlight=False, soft_wrap=True)


def render_groups(table: Any, max_links: int) -> None:
    """``mechsyn synth groups``: paper 000's table, one row per group size n_f."""
    console.print(f"W0 = {table.W0}, A = {table.actuators}: W_f = -(W0 - A) = {table.W_f}; "
                  f"the base needs m_0 = 2(W0 - 1) = {table.m_0} free leashes", highlight=False)
    t = Table(title="Groups to attach (paper 000)")
    for col in ("n_f", "P_f", "m_f"):
        t.add_column(col, justify="right")
    t.add_column("conditions")
    by_n = {r.n_f: r for r in table.rows}
    for n in range(1, max_links + 1):
        r = by_n.get(n)
        if r is None:
            t.add_row(str(n), "-", "-", "no integer P_f")
        else:
            needs = f"not met (needs P_f >= {2 * (table.W0 - 1) + n - 1}, m_f >= {table.m_0})"
            t.add_row(str(n), str(r.P_f), str(r.m_f), "met" if r.meets_conditions else needs)
    console.print(t)


SHORT_TITLES = {
    "chebyshev": "Chebyshev", "grubler": "Grübler", "malyshev": "Malyshev",
    "somov_malyshev": "Somov-Malyshev", "gokhman_contours": "Gokhman K", "scheme_check": "scheme check",
    "ozol_redundant": "Ozol q", "redundant_from_mobility": "S from W",
}


def _fmt(x: float | None) -> str:
    if x is None:
        return "n/a"
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


#: what the symbols of the formula tables count (the tables' caption, in this order)
SYMBOLS = {"W": "W: mobility", "K": "K: independent contours", "q": "q, S: redundant constraints",
           "S": "S: redundant constraints", "p": "scheme check: yes when pairs = links + contours - 1"}


def _formula_table(a: StructuralAnalysis, keys: list[str], title: str, rank: Any = None) -> None:
    from mechsyn.structure.report import formula_reasons, formula_title, formula_value_text

    values = {key: formula_value_text(key, a.formulas[key].value) for key in keys}
    symbols = {a.formulas[k].expression.split(" ", 1)[0] for k in keys}
    if "S" in symbols and "q" in symbols:
        symbols.discard("S")
    elif "S" in symbols:
        symbols.discard("q")
    caption = "; ".join(text for s, text in SYMBOLS.items() if s in symbols)
    t = Table(title=title, show_lines=False, caption=caption or None, caption_justify="left")
    t.add_column("formula", no_wrap=True)
    t.add_column("expression", overflow="fold")  # the long expressions wrap, numbers never do
    t.add_column("value", justify="right", no_wrap=True, min_width=max(map(len, ["value", *values.values()])))
    for key in keys:
        t.add_row(formula_title(SHORT_TITLES.get(key, key), a.formulas[key]), a.formulas[key].expression, values[key])
    console.print(t)
    for why, ks in formula_reasons(a, keys, rank):
        note(f"{', '.join(SHORT_TITLES.get(k, k) for k in ks)}: {why}", "differs:")


def _summary_line(line: dict[str, Any]) -> None:
    """A line under the formula tables: what it counts, its value, the reason it differs."""
    console.print(escape("\n".join(wrap_lines(f"{line['label']}: {line['text']}", "", "  "))), highlight=False,
                  soft_wrap=True)
    if line["why_it_differs"]:
        note(line["why_it_differs"], "  differs:")


def note(text: str, label: str = "note:") -> None:
    """A note wrapped at word boundaries to the console's width (80 columns in a pipe), its
    continuation lines indented under the text; a word longer than a line is cut."""
    lead = f"{label} " if label else ""
    lines = wrap_lines(text, lead, " " * len(lead))
    body = escape("\n".join(lines))
    if label:
        body = f"[dim]{escape(label)}[/]" + body[len(escape(label)):]
    console.print(body, highlight=False, soft_wrap=True)


def wrap_lines(text: str, first: str = "", rest: str = "") -> list[str]:
    """``text`` in lines of the console's width, broken at spaces only (not at hyphens)."""
    import textwrap

    return textwrap.wrap(text, width=max(console.width, 20), initial_indent=first, subsequent_indent=rest,
                         break_on_hyphens=False)


def render(a: StructuralAnalysis, title_prefix: str = "", rank: Any = None, verdict_text: str | None = None,
           drives_text: str | None = None) -> None:
    """``mechsyn analyze``: the verdict, the formulas of the file's own kind, then (planar
    files) their spatial reading with paper 003's contours, redundancy and drives."""
    from mechsyn.structure.report import READINGS, SPATIAL_OF_PLANAR, formula_sections, formula_summary

    pbc = ", ".join(f"p{k} = {v}" for k, v in a.pairs_by_class.items())
    head = (f"[bold]{title_prefix}{safe(a.name)}[/]\n{a.kind} mechanism: n = {a.moving_links} moving links "
            f"(N = {a.links_with_frame}), {a.pairs} pairs ({pbc}), K = {a.independent_contours} contours")
    if verdict_text:
        head += f"\n[bold]verdict:[/] {escape(verdict_text)}"
    if drives_text:
        head += f"\n[bold red]drives:[/] {escape(drives_text)}"
    console.print(Panel(head, expand=False))
    own, spatial = formula_sections(a)
    _formula_table(a, own, f"Formulas ({READINGS['planar' if a.kind == 'planar' else 'spatial']})", rank)
    summary = formula_summary(a, rank)
    _summary_line(summary["mobility"])
    _summary_line(summary["drives"])
    if spatial:
        console.print()
        console.print(f"[bold]{SPATIAL_OF_PLANAR[0]}[/]", highlight=False)
        note(SPATIAL_OF_PLANAR[1], "")
        _formula_table(a, spatial, "Formulas (spatial reading)", rank)
    if a.contours:
        _render_contours(a)
    if a.contours:
        _summary_line(summary["redundancy"])
    if a.external is not None:
        e = a.external
        console.print(f"external (paper 002): S_a = {e.S_a}, W_f = {e.W_f}, W_rob = {e.W_rob}, "
                      f"W_a = {e.W_a}, S_ai = {e.S_ai}", highlight=False)
        console.print(f"  {e.external_redundant.expression}\n  {e.system_redundant.expression}", highlight=False)
    for n in a.notes:
        note(n)
    for name, sub in a.states.items():
        console.print()
        render(sub, title_prefix=f"state '{safe(name)}': ")


def _render_contours(a: StructuralAnalysis) -> None:
    from mechsyn.structure.report import CONTOUR_READING, pair_list
    c = Table(title=f"Contours (paper 003, sequential reading{CONTOUR_READING[a.kind]})")
    for col in ("#", "joints", "new pairs", "n_j", "n_k", "S_j", "idle", "T_j", "Z_j", "A_j"):
        c.add_column(col, justify="right" if col not in ("joints", "new pairs") else "left")
    for r in a.contours:
        c.add_row(f"{r.index}{'' if r.from_file else '*'}", " ".join(r.joints), pair_list(r.new_pairs),
                  str(r.n_j), str(r.n_k), str(r.S), str(r.idle_mobilities), _fmt(r.T), str(r.Z), str(r.A))
    console.print(c)
    if a.contours_chosen_by_program:
        console.print("  * contour chosen by the program")
    for r in a.contours:
        console.print(escape("\n".join(wrap_lines(f"{r.S_expression};  {r.T_expression}", "  ", "    "))),
                      highlight=False, soft_wrap=True)


def render_remedies(remedies: list[Remedy]) -> None:
    t = Table(title="Remedies (pair-class changes; fewest changes first)")
    t.add_column("#", justify="right")
    t.add_column("changes")
    t.add_column("S_j after", justify="right")
    t.add_column("W after")
    for k, r in enumerate(remedies, 1):
        t.add_row(str(k), "\n".join(c.describe() for c in r.changes),
                  ", ".join(str(x.S) for x in r.analysis.contours),
                  r.analysis.formulas["somov_malyshev"].expression)
    if not remedies:
        console.print("No class-change remedy: nothing to remedy, or a planar mechanism "
                      "(its pairs' planar classes are fixed).")
    else:
        console.print(t)
        left = remedies[0].analysis.metric_constraints
        if left:
            console.print(f"note: {left:g} metric constraint(s) remain in every variant: class changes cannot "
                          "remove them; change the structure (e.g. replace the duplicating link by a two-link "
                          "group, as paper 003 does for fig. 4).", highlight=False)


def render_rank(ra: RankAnalysis, comparisons: list[Comparison] | None, title: str = "") -> None:
    from mechsyn.structure.rank import rank_summary_lines
    lines = [f"[bold red]{x}[/]" if x.startswith("SINGULAR") else x for x in rank_summary_lines(ra)]
    console.print(Panel.fit("[bold]Rank method (screw theory)" + (f": {title}" if title else "") + "[/]\n"
                            + "\n".join(lines), border_style="cyan"), highlight=False)
    if any(c.redundant for c in ra.contours):
        t = Table(title="Redundant constraints located (rank, contours in order)")
        for col in ("#", "joints", "q_j", "redundant directions", "why"):
            t.add_column(col, justify="right" if col in ("#", "q_j") else "left")
        for c in ra.contours:
            t.add_row(str(c.index), " ".join(c.joints), str(c.redundant), "\n".join(c.directions), c.reason)
        console.print(t)
    if comparisons:
        t = Table(title="Formulas and rank side by side", expand=True)
        words = max(len(w) for c in comparisons for w in c.quantity.split())
        t.add_column("quantity", width=words)  # words whole; text columns share the rest, numbers never wrap
        t.add_column("formula", ratio=2)
        t.add_column("value", no_wrap=True)
        t.add_column("rank", justify="right", no_wrap=True)
        t.add_column("why they differ", ratio=3)
        for c in comparisons:
            fv = "n/a" if c.formula_value is None else _fmt(c.formula_value)
            mark = "" if c.agree else "[yellow]≠[/] "
            t.add_row(c.quantity, c.formula, fv, f"{mark}{c.rank_value}", c.why)
        console.print(t)
    for n in ra.notes:
        note(n)


def render_remedy_checks(checks: list[tuple[int, Remedy, RemedyCheck]]) -> None:
    kept = [c for c in checks if c[2].accepted]
    if kept:
        console.print(f"rank method: the {len(kept)} variant(s) above are confirmed "
                      f"({kept[0][2].reason.removeprefix('confirmed: ')})", highlight=False)
    dropped = [c for c in checks if not c[2].accepted]
    if dropped:
        console.print(f"[bold]dropped by the rank method ({len(dropped)}):[/]")
    for _, r, chk in dropped:
        console.print(f"  - {'; '.join(c.describe() for c in r.changes)}: [red]{chk.reason}[/]", highlight=False)


#: From this many joints, ``analyze`` says the size and shows the rank method's stages on stderr.


def render_report(report: StructureReport) -> None:
    """The terminal tables of a structural report."""
    ra, method = report.rank, report.method
    v = report.verdict
    drives = v["over_actuation"]
    text = v["text"].removesuffix(f". {drives}") if drives else v["text"]  # said on a line of its own
    if method != "rank":
        render(report.analysis, rank=ra, verdict_text=text, drives_text=drives)
    else:
        console.print(Panel(f"[bold]{safe(report.analysis.name)}[/]\n[bold]verdict:[/] {escape(text)}"
                            + (f"\n[bold red]drives:[/] {escape(drives)}" if drives else ""), expand=False))
    for n in report.notes:
        note(n)
    if ra is not None:
        console.print()
        render_rank(ra, report.comparisons if method == "both" else None)
        for name, (sr, why) in report.state_ranks.items():
            if sr is not None:
                render_rank(sr, None, title=f"state '{name}'")
            else:
                console.print(f"[dim]state '{name}': no rank analysis ({why})[/]", highlight=False)
    if report.remedies is not None:
        console.print()
        render_remedies(report.remedies)
        if report.checks:
            render_remedy_checks(report.checks)
