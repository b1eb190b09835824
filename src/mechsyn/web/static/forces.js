// The Forces tab: link masses and inertias and the loads, entered here and kept in the mechanism
// file (`links: [{name, mass, inertia}]`, `loads:`), gravity and the drive speed; the drive's
// torque (or force) and the joint reactions over the input (the library's `forces`: kinetostatics),
// plotted, and the reactions at the frame shown drawn as arrows on the canvas.
import { call } from "./api.js";
import { linkName } from "./draw.js";
import { chart } from "./plots.js";
import { h } from "./numeric.js";
import { lengthScale } from "./checks.js";

const num = (text) => { const v = Number(String(text).trim().replace(",", ".")); return String(text).trim() !== "" && Number.isFinite(v) ? v : null; };

// `ctx`: {$, state, render, edit, stepsFor, spatialLines}; returns {renderForces, forcesSoon, compute,
// arrows, cursor}. A spatial file gets `spatialLines()` instead (spatial_tabs.js: no spatial statics).
export function mountForces({ $, state, render, edit, stepsFor, spatialLines }) {
  const box = $("tab-forces");
  let timer = null, charts = [], asked = 0;

  function field(value, onValue, attrs = {}) {
    const i = h("input", null, { type: "text", inputMode: "decimal", value: value === undefined ? "" : String(value), ...attrs });
    i.onchange = () => { const v = num(i.value); if (v === null) { i.setCustomValidity("a number"); i.reportValidity(); } else onValue(v); };
    return i;
  }
  function setLinkAttr(m, name, key, v) {
    const i = m.links.findIndex((l) => linkName(l) === name);
    const l = typeof m.links[i] === "string" ? { name } : m.links[i];
    l[key] = v;
    m.links[i] = l;
  }

  function massTable(m) {
    const t = h("table", null, { className: "numtable" });
    t.dataset.table = "masses";
    const head = h("tr"); for (const c of ["link", "mass", "inertia about its centre"]) head.append(h("th", c)); t.append(head);
    for (const l of m.links) {
      const name = linkName(l);
      if (name === m.ground) continue;
      const tr = h("tr"); tr.dataset.row = name;
      const cells = [field(l.mass ?? 0, (v) => edit((n) => setLinkAttr(n, name, "mass", v)), { className: "mass" }),
        field(l.inertia ?? 0, (v) => edit((n) => setLinkAttr(n, name, "inertia", v)), { className: "inertia" })];
      cells[0].dataset.field = "mass"; cells[1].dataset.field = "inertia";
      tr.append(h("td", name), ...cells.map((c) => { const td = h("td"); td.append(c); return td; }));
      t.append(tr);
    }
    return t;
  }

  function loadList(m) {
    const ul = h("ul");
    (m.loads || []).forEach((ld, i) => {
      const f = ld.force || [0, 0];
      const li = h("li", `${ld.link}: force (${f[0]}, ${f[1]})${ld.point ? ` at ${ld.point}` : ld.at ? ` at (${ld.at})` : " at its centre"}` +
        (ld.moment ? `, moment ${ld.moment}` : "") + " ");
      const del = h("button", "Delete"); del.onclick = () => edit((n) => { n.loads.splice(i, 1); if (!n.loads.length) delete n.loads; });
      li.append(del); ul.append(li);
    });
    const link = h("select", null, { id: "load-link" });
    for (const l of m.links) if (linkName(l) !== m.ground) link.append(h("option", linkName(l), { value: linkName(l) }));
    const where = h("select", null, { id: "load-point" });
    const fillWhere = () => {
      where.replaceChildren(h("option", "centre", { value: "" }),
        ...Object.entries(m.points || {}).filter(([, p]) => p.link === link.value).map(([n]) => h("option", n, { value: n })));
    };
    link.onchange = fillWhere; fillWhere();
    const fx = h("input", null, { id: "load-fx", value: "0", size: 4 }), fy = h("input", null, { id: "load-fy", value: "0", size: 4 });
    const mz = h("input", null, { id: "load-moment", value: "0", size: 4 });
    const add = h("button", "Add load", { id: "load-add" });
    add.onclick = () => {
      const F = [num(fx.value), num(fy.value)], M = num(mz.value);
      if (F.includes(null) || M === null) return;
      edit((n) => { n.loads = n.loads || []; n.loads.push({ link: link.value, force: F, moment: M, ...(where.value ? { point: where.value } : {}) }); });
    };
    const p = h("p"); p.append("on ", link, " at ", where, " Fx ", fx, " Fy ", fy, " M ", mz, " ", add);
    return [ul, p];
  }

  async function compute() {
    const mech = state.mech, ask = ++asked;  // only the latest request's answer is shown
    if (!mech || mech.kind !== "planar" || !mech.joints.some((j) => j.actuated)) { state.forces = null; return renderForces(); }
    try {
      const r = await call("/api/studio/forces", { mechanism: mech, steps: stepsFor(mech), speed: num($("drive-speed").value) ?? 1,
        gravity: $("forces-gravity").checked ? [0, -9.81] : [0, 0] });
      if (mech !== state.mech || ask !== asked) return;
      state.forces = { mech, r };
    } catch (e) {
      if (ask !== asked) return;
      state.forces = { mech, error: e.error || String(e) };
    }
    renderForces(); render();
  }
  function forcesSoon() { clearTimeout(timer); if (box.classList.contains("on")) timer = setTimeout(compute, 150); }

  function renderForces() {
    const m = state.mech;
    if (!m) return;
    if (m.kind !== "planar") { box.replaceChildren(...spatialLines()); return; }
    const out = [h("h3", "Masses (kg, kg·m² in SI)"), massTable(m), h("h3", "Loads (N, N·m in SI)"), ...loadList(m)];
    const opts = h("p");
    const g = $("forces-gravity") || h("input", null, { type: "checkbox", id: "forces-gravity" });
    g.onchange = compute;
    opts.append(g, " gravity 9.81 down (−y); drive speed as in the Plots tab");
    out.push(opts);
    const f = state.forces;
    if (f && f.mech === m && f.error) out.push(h("p", f.error, { className: "err" }));
    else if (f && f.mech === m) {
      const r = f.r, xs = r.input.values, xunit = r.input.unit === "deg" ? "°" : "units", xname = r.input.joint;
      const common = { xs, xname, xunit, k: state.frame, ranges: [], width: box.clientWidth - 24, group: "forces", onPick: (row) => { state.frame = row; render(); } };
      charts = [];
      for (const [j, d] of Object.entries(r.drives)) {
        const moment = d.kind === "moment", second = (m.joints.find((q) => q.id === j) || { links: ["", "its second link"] }).links[1];
        charts.push(chart({ ...common, id: `drive ${j}`, title: `${moment ? "drive torque" : "drive force"} at ${j}`, yunit: moment ? "N·m" : "N",
          note: moment ? `the moment the drive applies to ${second}, counter-clockwise positive` : `the force the drive applies to ${second}, positive along the slide's direction`,
          series: [{ name: moment ? `τ ${j}` : `F ${j}`, values: d.value }] }));
      }
      const joints = Object.entries(r.joints);
      charts.push(chart({ ...common, id: "reactions", title: "joint reactions |F|", yunit: "N", note: "the force of each joint's first link on its second",
        series: joints.map(([j, d]) => ({ name: j, values: d.magnitude })) }));
      charts.push(chart({ ...common, id: "reaction components", title: "joint reactions Fx, Fy", yunit: "N", note: "on each joint's second link (the first gets −F)",
        series: joints.flatMap(([j, d]) => [0, 1].map((c) => ({ name: `${j} F${"xy"[c]}`, values: d.force.map((F) => (F ? F[c] : null)) }))) }));
      out.push(h("p", `Sign convention: ${r.convention}; moments counter-clockwise positive. Mean and RMS are over the rows, equally spaced in ${xname} (time averages at a constant drive speed).`, { className: "muted" }));
      out.push(...charts);
      for (const n of r.notes || []) out.push(h("p", n, { className: "muted" }));
      if (r.indeterminate) out.push(h("p", "statically indeterminate: the reactions shown are one of many (redundant constraints)", { className: "muted" }));
    } else out.push(h("p", m.joints.some((j) => j.actuated) ? "computing…" : "no drive yet", { className: "muted" }));
    box.replaceChildren(...out);
  }

  // The reactions at frame k as arrows {at, vec} in model units (the largest over the sweep drawn
  // a quarter of the length scale long), for the drawing.
  function arrows(k, jointsAt) {
    const f = state.forces;
    if (!f || f.mech !== state.mech || !f.r || !box.classList.contains("on")) return [];
    const joints = jointsAt();
    let big = 0;
    for (const d of Object.values(f.r.joints)) for (const v of d.magnitude) if (v !== null && v > big) big = v;
    if (!(big > 0)) return [];
    const s = (0.25 * lengthScale(state.mech)) / big, out = [];
    for (const [j, d] of Object.entries(f.r.joints)) {
      const F = d.force[k], at = joints[j];
      if (F && at) out.push({ id: j, at, vec: [F[0] * s, F[1] * s] });
    }
    return out;
  }

  // The charts' slider lines follow the frame shown (the tab itself is redrawn only when the mechanism changes).
  function cursor(k) {
    const f = state.forces;
    if (!f || !f.r || !box.classList.contains("on")) return;
    for (const c of charts) c.cursor(k);
  }

  return { renderForces, forcesSoon, compute, arrows, cursor };
}
