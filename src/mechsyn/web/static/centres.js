// The Design tab (issue 40): the file's length unit; the instant centres of every pair of links
// at the frame shown (POST /api/design/centres: mechsyn.kinematics.centres, Kennedy's theorem),
// drawn as [data-centre] marks and listed with the velocity ratio each gives; a cam's profile
// drawn on its link (POST /api/design/cams).
import { call } from "./api.js";
import { el } from "./draw.js";
import { h } from "./numeric.js";


// ctx: {$, state, render, setMech}
export function mountCentres({ $, state, render, setMech }) {
  const fmt = (v) => String(+(+v).toPrecision(4));
  const cs = { mech: null, key: "", list: null, error: null, cams: null, camsFor: null };
  window.__centres = cs; // for tests (read-only use)

  $("unit").onchange = () => {
    const m = JSON.parse(JSON.stringify(state.mech));
    if ($("unit").value) m.unit = $("unit").value; else delete m.unit;
    delete m.units;
    setMech(m, { keepFrame: true });
  };
  $("show-centres").onchange = () => { cs.key = ""; update(); render(); };

  // the drive values of the frame shown (the first drive's sweep, the others as drawn)
  function inputsNow() {
    const sim = state.sim;
    if (!sim || !sim.assembled[state.frame]) return null;
    return { [sim.input.joint]: sim.input.values[state.frame] };
  }

  function update() {
    const m = state.mech;
    if (!m) return;
    const unit = m.unit || m.units || "";
    if ($("unit").value !== unit) $("unit").value = unit;
    if (m.kind === "planar" && cs.camsFor !== m) {
      cs.camsFor = m; cs.cams = null;
      if (m.joints.some((j) => j.type === "cam")) call("/api/design/cams", { mechanism: m }).then((r) => { if (cs.camsFor === m) { cs.cams = r.cams; render(); } }, () => {});
    }
    if (!$("show-centres").checked || m.kind !== "planar" || state.dragging || state.playing) { if (!$("show-centres").checked) $("centres").replaceChildren(); return; }
    const inputs = inputsNow();
    const key = JSON.stringify(inputs);
    if (cs.mech === m && cs.key === key) return;
    cs.mech = m; cs.key = key;
    call("/api/design/centres", { mechanism: m, inputs }).then((r) => {
      if (cs.mech !== m || cs.key !== key) return;
      cs.list = r.centres; cs.error = null; list(); render();
    }, (e) => { if (cs.mech === m) { cs.list = null; cs.error = e.error || String(e); list(); render(); } });
  }

  function list() {
    if (cs.error) { $("centres").replaceChildren(h("p", cs.error, { className: "err" })); return; }
    const t = h("table", null, { className: "numtable" });
    t.dataset.table = "centres";
    const head = h("tr"); for (const c of ["centre", "links", "where", "kind", "ω₂/ω₁"]) head.append(h("th", c)); t.append(head);
    for (const c of cs.list || []) {
      const tr = h("tr"); tr.dataset.centre = c.numbers.join("");
      const where = c.point ? `(${fmt(c.point[0])}, ${fmt(c.point[1])})` : c.direction ? `at ∞ along (${fmt(c.direction[0])}, ${fmt(c.direction[1])})` : "—";
      const ratio = c.ratio === null ? "" : fmt(Math.abs(c.ratio) < 1e-12 ? 0 : c.ratio);
      tr.append(h("td", `P${c.numbers.join("")}`), h("td", `${c.links[0]} (${c.numbers[0]}), ${c.links[1]} (${c.numbers[1]})`),
        h("td", where), h("td", c.kind + (c.joint ? ` (${c.joint})` : "")), h("td", ratio));
      t.append(tr);
    }
    $("centres").replaceChildren(t, h("p", "Pij: the instant centre of links i and j (numbered in file order). ω₂/ω₁ is the second link's angular velocity over the first's (both against the frame); by Kennedy's theorem the centres of any three links lie on one line.", { className: "muted" }));
  }

  // the canvas: cam profiles (always), instant centres (when asked)
  state.overlays.centres = (layer, v, pos, labels) => {
    const m = state.mech;
    if (!m || m.kind !== "planar") return;
    for (const cam of cs.camsFor === m ? cs.cams || [] : []) drawCam(layer, v, pos, cam);
    if (!$("show-centres").checked || cs.mech !== m || !cs.list || state.dragging) return;
    for (const c of cs.list) {
      if (!c.point) continue;
      const [x, y] = v.toScreen(c.point);
      if (!Number.isFinite(x) || !Number.isFinite(y) || Math.abs(x) > 1e5 || Math.abs(y) > 1e5) continue;
      el("rect", { x: x - 4, y: y - 4, width: 8, height: 8, class: "centre-mark", "data-centre": c.numbers.join("") }, layer);
      labels(layer, x + 6, y + 15, `P${c.numbers.join("")}`).setAttribute("class", "label centre-label");
    }
  };

  // a cam's profile turned with its link about its pivot (the link's angle against the drawn one)
  function drawCam(layer, v, pos, cam) {
    const sim = state.sim, k = state.frame;
    let turn = 0;
    const lk = sim && sim.links && sim.links[cam.link];
    if (lk && lk.angle && lk.angle[k] !== null && !state.dragging) turn = ((lk.angle[k] - lk.angle[state.home]) * Math.PI) / 180;
    const drawn = state.mech.joints.find((j) => j.id === cam.pivot);
    const p0 = drawn ? drawn.point : [0, 0], p1 = cam.pivot && pos.joints[cam.pivot] ? pos.joints[cam.pivot] : p0;
    const c = Math.cos(turn), s = Math.sin(turn);
    const pts = cam.points.map(([x, y]) => { const dx = x - p0[0], dy = y - p0[1]; return v.toScreen([p1[0] + c * dx - s * dy, p1[1] + s * dx + c * dy]); });
    el("polygon", { points: pts.map((p) => p.map((q) => q.toFixed(1)).join(",")).join(" "), class: "cam-profile", "data-cam": cam.joint }, layer);
  }

  return { update, notes: () => [] };
}
