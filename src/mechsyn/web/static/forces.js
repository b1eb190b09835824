// The Forces tab: link masses and inertias and the loads, entered here and kept in the mechanism
// file (`links: [{name, mass, inertia}]`, `loads:`), gravity and the drive speed; the drive's
// torque (or force) and the joint reactions over the input (the library's `forces`: kinetostatics),
// plotted, and the reactions at the frame shown drawn as arrows on the canvas.
import { call } from "./api.js";
import { linkName, plot, el } from "./draw.js";
import { h } from "./numeric.js";
import { lengthScale } from "./checks.js";

const num = (text) => { const v = Number(String(text).trim().replace(",", ".")); return String(text).trim() !== "" && Number.isFinite(v) ? v : null; };

// `ctx`: {$, state, render, edit, stepsFor, spatialLines}; returns {renderForces, forcesSoon, compute,
// arrows, cursor}. A spatial file gets `spatialLines()` instead (spatial_tabs.js: no spatial statics).
export function mountForces({ $, state, render, edit, stepsFor, spatialLines }) {
  const box = $("tab-forces");
  let timer = null;

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
    const mech = state.mech;
    if (!mech || mech.kind !== "planar" || !mech.joints.some((j) => j.actuated)) { state.forces = null; return renderForces(); }
    try {
      const r = await call("/api/studio/forces", { mechanism: mech, steps: stepsFor(mech), speed: num($("drive-speed").value) ?? 1,
        gravity: $("forces-gravity").checked ? [0, -9.81] : [0, 0] });
      if (mech !== state.mech) return;
      state.forces = { mech, r };
    } catch (e) { state.forces = { mech, error: e.error || String(e) }; }
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
      const r = f.r, xs = r.input.values, unit = r.input.unit === "deg" ? "°" : "units";
      for (const [j, d] of Object.entries(r.drives)) {
        const what = d.kind === "moment" ? "drive torque" : "drive force";
        out.push(h("p", `${what} at ${j} (${d.kind === "moment" ? "N·m" : "N"} in SI) against ${r.input.joint} (${unit})`));
        const s = el("svg", { "data-plot": `drive ${j}` });
        plot(s, xs, [{ name: j, values: d.value }], state.frame, [], { x: `${r.input.joint} (${unit})`, y: d.kind === "moment" ? "N·m" : "N" });
        out.push(s);
      }
      out.push(h("p", `joint reactions |F| (N in SI) against ${r.input.joint} (${unit})`));
      const s = el("svg", { "data-plot": "reactions" });
      plot(s, xs, Object.entries(r.joints).map(([j, d]) => ({ name: j, values: d.magnitude })), state.frame, [], { x: `${r.input.joint} (${unit})`, y: "N" });
      out.push(s);
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

  // The plots' cursors follow the frame shown (the tab itself is redrawn only when the mechanism changes).
  function cursor(k) {
    const f = state.forces;
    if (!f || !f.r || !box.classList.contains("on")) return;
    const x = f.r.input.values[k];
    for (const s of box.querySelectorAll("svg")) {
      const c = s.querySelector("[data-cursor]");
      if (!c || !s.__map || x === undefined) continue;
      const px = s.__map.X(x).toFixed(1);
      c.setAttribute("x1", px); c.setAttribute("x2", px); c.setAttribute("data-cursor", k);
    }
  }

  return { renderForces, forcesSoon, compute, arrows, cursor };
}
