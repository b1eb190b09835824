// The Plots and Forces tabs of a spatial file (the planar ones are studio.js's renderPlots and
// forces.js). Plots: the spatial engine's sweep (POST /api/spatial/simulate, web/_spatial.py: the
// SpatialSimulation's to_dict, the 3-D view's rows) drawn against the input: every pair's
// angle (or slide), a named point's coordinates, velocity and acceleration, a link's angular
// velocity and acceleration, with units, the events (singular positions, dead points) marked and
// the input slider's row as the cursor. Forces: spatial statics are not in the library; the tab
// says so in one line and gives what the rank method reads (finite mobility, idle motions,
// redundant constraints: whether the reactions would be unique).
import { h } from "./numeric.js";
import { chart } from "./plots.js";

const XYZ = ["x", "y", "z"];

// `ctx`: {$, state, render, showTab}; returns {renderPlots, forcesLines}.
// `motionOf(mech)`: the 3-D view's request of the sweep (view3d.js), shared.
export function mountSpatialTabs({ $, state, render, showTab, motionOf }) {
  const sp = { mech: null, data: null, error: null, loading: false, draws: 0 };
  let charts = [];
  window.__spatialPlots = sp; // for tests (read-only use)

  function fetchFor(m) {
    if (sp.mech === m) return;
    sp.mech = m; sp.data = null; sp.error = null; sp.loading = true;
    motionOf(m).then((d) => {
      if (sp.mech !== m) return;
      sp.data = d; sp.loading = false; renderPlots();
    }, (e) => {
      if (sp.mech !== m) return;
      sp.error = e; sp.loading = false; renderPlots();
    });
  }

  // A pair's value is a slide (a P pair's, or a C or H pair's "<id>/slide") or an angle.
  const kindOf = (key) => (key.endsWith("/slide") || (state.mech.joints.find((j) => j.id === key) || {}).type === "P" ? "slide" : "angle");
  // The link a point rides on: a named point's, or a joint's second link.
  const linkOf = (name) => ((state.mech.points || {})[name] || {}).link || (state.mech.joints.find((j) => j.id === name) || { links: [] }).links[1];

  // The quantities offered: the pairs' angles (and slides), each point, each moving link.
  function options(d) {
    const kinds = new Set(Object.keys(d.joints).map(kindOf));
    const out = [];
    if (kinds.has("angle")) out.push(["pairs:angle", "joint angles"]);
    if (kinds.has("slide")) out.push(["pairs:slide", "joint slides"]);
    const m = state.mech, named = Object.keys(m.points || {}); // the 3-D view's paths: the named points, else the joints off the frame
    const shown = (n) => (named.length ? named.includes(n) : !(m.joints.find((j) => j.id === n) || { links: [m.ground] }).links.includes(m.ground));
    for (const n of Object.keys(d.points).filter(shown)) out.push([`point:${n}`, `point ${n}`]);
    for (const n of Object.keys(d.links)) out.push([`link:${n}`, `link ${n}`]);
    return out;
  }

  // [title, unit, series] of each plot of the quantity chosen, at drive speed w.
  function plotsOf(d, what, w) {
    const [kind, name] = what.split(":");
    const rot = d.input.type !== "P", rate = rot ? "rad/s" : "units/s", at = `at ${d.input.joint} = ${w} ${rate}`;
    const comp = (rows, f) => XYZ.map((c, i) => ({ name: c, values: rows.map((v) => (v ? v[i] * f : null)) }));
    if (kind === "pairs") {
      const ps = Object.entries(d.joints).filter(([k]) => kindOf(k) === name);
      const unit = name === "angle" ? "°" : "units";
      return [[`${name === "angle" ? "joint angles" : "joint slides"} from the drawn pose`, unit, ps.map(([k, values]) => ({ name: k, values }))]];
    }
    if (kind === "point") {
      const p = d.points[name];
      return [[`position of ${name} on ${linkOf(name)}`, "units", comp(p.position, 1)],
        [`velocity of ${name}, ${at}`, "units/s", comp(p.velocity, w)],
        [`acceleration of ${name}, ${at}`, "units/s²", comp(p.acceleration, w * w)]];
    }
    const l = d.links[name];
    return [[`angular velocity of ${name}, ${at}`, "rad/s", comp(l.angular_velocity, w)],
      [`angular acceleration of ${name}, ${at}`, "rad/s²", comp(l.angular_acceleration, w * w)]];
  }

  function renderPlots() {
    const m = state.mech, sel = $("plot-what"), box = $("plots");
    if (!m || m.kind === "planar" || !$("tab-plots").classList.contains("on")) return;
    fetchFor(m);
    if (sp.error) {
      box.replaceChildren(h("p", `no spatial motion to plot: ${sp.error.error || sp.error}${sp.error.hint ? " — fix: " + sp.error.hint : ""}`, { className: "muted" }));
      return;
    }
    const d = sp.data;
    if (!d) { box.replaceChildren(h("p", "simulating the spatial mechanism…", { className: "muted" })); return; }
    const opts = options(d);
    if ([...sel.options].map((o) => o.value).join() !== opts.map((o) => o[0]).join()) {
      const keep = sel.value;
      sel.replaceChildren(...opts.map(([v, t]) => h("option", t, { value: v })));
      sel.value = opts.some((o) => o[0] === keep) ? keep : opts[0][0];
    }
    const xs = d.input.values, k = Math.max(0, Math.min(xs.length - 1, state.frame | 0));
    const deg = d.input.unit === "deg", xunit = deg ? "°" : "units", w = Number($("drive-speed").value) || 1;
    const marks = d.events.filter((e) => e.kind !== "reassembled")
      .map((e) => ({ x: xs[e.index], kind: e.kind, text: `${e.kind} at ${d.input.joint} = ${(+xs[e.index]).toFixed(2)}: ${e.message}` }));
    const width = box.clientWidth - 4, onPick = (row) => { state.frame = row; render(); };
    charts = plotsOf(d, sel.value, w).map(([title, unit, series]) => chart({ title, xs, xname: d.input.joint, xunit, yunit: unit,
      series, note: title.includes("drawn pose") ? "" : "input from the drawn pose", k, ranges: d.working_ranges, marks, onPick, width, group: "plots" })); // plots.js
    const out = [...charts];
    for (const e of d.events) out.push(h("p", `${e.kind} at ${Object.entries(e.input).map(([j, v]) => `${j} = ${(+v).toFixed(2)}`).join(", ")}: ${e.message}`, { className: "muted" }));
    for (const n of d.notes) out.push(h("p", n, { className: "muted" }));
    box.replaceChildren(...out);
    sp.draws += 1;
  }

  // The plots' cursors follow the input slider (the 3-D view's row); the plots are drawn again only
  // when the mechanism or the quantity changes.
  function cursor() {
    const d = sp.data;
    if (!d || sp.mech !== state.mech || !$("tab-plots").classList.contains("on")) return;
    const k = Math.max(0, Math.min(d.input.values.length - 1, state.frame | 0));
    for (const c of charts) c.cursor(k);
  }

  // The Forces tab of a spatial file: one line on what is missing, then what the rank method reads.
  function forcesLines() {
    const a = state.analysis, r = a && a.rank, out = [];
    const line = h("p", "Forces: spatial statics are not in mechsyn yet (the Forces tab computes planar files). "
      + "What the structure says about this file's forces:", { className: "note" });
    line.dataset.spatialForces = "";
    out.push(line);
    if (!r) out.push(h("p", a && a.error ? `no rank reading: ${a.error}` : a ? `no rank reading: ${a.rank_unavailable || "unknown"}` : "reading the structure…", { className: "muted" }));
    else {
      const idle = (r.idle_mobilities || []).length, q = r.redundant_constraints;
      const ul = h("ul");
      ul.append(h("li", r.mobility_reading || `instantaneous mobility ${r.mobility}`),
        h("li", `${r.mobility - idle} useful + ${idle} idle motion(s)${idle ? ": an idle motion carries no load and needs no drive" : ""}`),
        h("li", q > 0 ? `${q} redundant constraint(s): statically indeterminate, the joint reactions would not be unique (they depend on fits and elasticity)`
          : "no redundant constraint: statically determinate, the reactions would be unique"),
        h("li", r.actuation_note || ""));
      out.push(ul);
    }
    const go = h("button", "Open the Analysis tab");
    go.onclick = () => showTab("analysis");
    out.push(go);
    return out;
  }

  return { renderPlots, cursor, forcesLines };
}
