// Robots (issue 40): every drive of a multi-drive mechanism has its own slider in the player
// (input[data-drive]; the others held), and a parallel mechanism is driven by its tool point:
// typed (inputs tool-x, tool-y, tool-z in the Design tab) or dragged (the orange ring on the
// planar canvas), the drives follow by the library's inverse kinematics
// (POST /api/design/reach: mechsyn.kinematics.inverse), the workspace boundary said in the
// banner where the point cannot follow. Each move is one undo step; the drawn pose moves.
import { call } from "./api.js";
import { makeView } from "./draw.js";
import { h } from "./numeric.js";


// ctx: {$, state, render, setMech}
export function mountRobot({ $, state, render, setMech }) {
  const fmt = (v) => String(+(+v).toPrecision(6));
  const bar = h("span"); bar.id = "drives";
  $("input-slider").before(bar);
  const box = h("div"); box.id = "robot-box";
  const rb = { base: null, info: null, values: {}, note: null, mine: null, busy: false, next: null, tool: null };
  window.__robot = rb; // for tests (read-only use)

  // A mechanism opened or edited elsewhere: its drives and tool points asked for once.
  function update() {
    const m = state.mech;
    if (!m || m === rb.mine || m === rb.base) return;
    rb.base = m; rb.info = null; rb.note = null;
    const drives = m.joints.filter((j) => j.actuated);
    if (drives.length < 2) { bar.replaceChildren(); box.replaceChildren(); return; }
    call("/api/design/drives", { mechanism: m }).then((info) => {
      if (rb.base !== m) return;
      rb.info = info; rb.values = Object.fromEntries(info.drives.map((d) => [d.id, d.value]));
      if (!rb.tool || !info.tools.some((t) => t.id === rb.tool)) rb.tool = info.tools.length ? info.tools[0].id : null;
      renderBar(); renderBox();
    }, (e) => { rb.note = e.error || String(e); renderBox(); });
  }

  function renderBar() {
    const info = rb.info;
    bar.replaceChildren(...info.drives.map((d) => {
      const r = d.type === "P" ? info.length_scale / 2 : 180;
      const s = h("input", null, { type: "range", min: d.value - r, max: d.value + r, step: d.type === "P" ? r / 180 : 0.5, value: rb.values[d.id] });
      s.dataset.drive = d.id; s.title = `drive ${d.id}`;
      let before = null;
      s.addEventListener("pointerdown", () => { before = JSON.stringify(state.mech); });
      s.oninput = () => { rb.values[d.id] = +s.value; move({ values: { ...rb.values } }); };
      s.onchange = () => { if (before) { state.undo.push(before); state.redo = []; before = null; } };
      const l = h("label", `${d.id} `); l.append(s);
      return l;
    }));
  }

  // one request in flight; the latest wish next
  async function move(wish) {
    if (rb.busy) { rb.next = wish; return; }
    rb.busy = true;
    try {
      const out = wish.values ? await call("/api/design/pose", { mechanism: rb.base, values: wish.values })
        : await call("/api/design/reach", { mechanism: rb.base, point: wish.point, target: wish.target });
      rb.note = out.message || null;
      if (out.values) Object.assign(rb.values, out.values);
      if (out.mechanism) { rb.mine = out.mechanism; setMech(out.mechanism, { record: !!wish.record, keepFrame: false }); }
      if (wish.target) syncSliders();
    } catch (e) { rb.note = e.error || String(e); }
    rb.busy = false;
    render(); renderBox();
    if (rb.next) { const n = rb.next; rb.next = null; move(n); }
  }

  function syncSliders() { for (const s of bar.querySelectorAll("input[data-drive]")) s.value = rb.values[s.dataset.drive]; }

  // the Design tab: the tool point chosen and typed
  function renderBox() {
    const info = rb.info;
    if (!info || !info.tools.length) { box.replaceChildren(...(rb.note ? [h("p", rb.note, { className: "err" })] : [])); return; }
    const sel = h("select", null, { id: "tool-point" });
    for (const t of info.tools) sel.append(h("option", t.id, { value: t.id, selected: t.id === rb.tool }));
    sel.onchange = () => { rb.tool = sel.value; renderBox(); render(); };
    const at = toolAt(true) || info.tools.find((t) => t.id === rb.tool).at;
    const inputs = at.map((c, k) => {
      const i = h("input", null, { value: fmt(c), size: 7, name: `tool-${"xyz"[k]}` });
      i.onchange = () => { const v = Number(i.value); if (!Number.isFinite(v)) return; const t = toolAt(true) || at.slice(); t[k] = v; move({ point: rb.tool, target: t, record: true }); };
      const l = h("label", ` ${"xyz"[k]} `); l.append(i); return l;
    });
    const p = h("p"); p.append("tool point ", sel, ...inputs);
    const out = [h("h3", "Drive by the tool point"), p,
      h("p", `Type where ${rb.tool} should go${info.spatial ? "" : " or drag its orange ring on the canvas"}: the drives follow (inverse kinematics); each drive also has its own slider below the drawing.`, { className: "muted" })];
    if (rb.note) out.push(h("p", rb.note, { className: "warn" }));
    box.replaceChildren(...out);
  }

  // where the tool point is drawn now (planar: the simulation's frame, else, or `drawn`, the file's pose)
  function toolAt(drawn = false) {
    const m = state.mech;
    if (!m || !rb.tool) return null;
    if (m.kind === "planar" && !drawn && state.simFor === m) {
      const sim = state.sim, k = state.frame;
      const src = sim && sim.points[rb.tool];
      if (src && src.position[k]) return src.position[k].slice();
    }
    const p = (m.points || {})[rb.tool];
    if (p) return p.at.slice();
    const j = m.joints.find((x) => x.id === rb.tool);
    return j ? j.point.slice() : null;
  }

  // the planar canvas: the tool point's ring, dragged
  state.overlays.robot = (layer, v) => {
    if (!rb.info || !rb.tool || state.mech.kind !== "planar") return;
    const p = toolAt();
    if (!p) return;
    const [x, y] = v.toScreen(p);
    const c = document.createElementNS("http://www.w3.org/2000/svg", "circle");
    Object.entries({ cx: x, cy: y, r: 13, class: "tool-target", "data-tool": rb.tool }).forEach(([k, val]) => c.setAttribute(k, val));
    layer.append(c);
  };
  const svg = $("canvas");
  let drag = null;
  svg.addEventListener("pointerdown", (ev) => {
    const t = ev.target.closest && ev.target.closest("[data-tool]");
    if (!t || state.mode !== "select") return;
    ev.stopPropagation(); ev.preventDefault();
    drag = { before: JSON.stringify(state.mech), base: rb.base };
    svg.setPointerCapture(ev.pointerId);
  }, { capture: true });
  svg.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    ev.stopPropagation();
    const r = svg.getBoundingClientRect();
    move({ point: rb.tool, target: makeView(svg, state.view).toWorld([ev.clientX - r.left, ev.clientY - r.top]) });
  }, { capture: true });
  const end = (ev) => { if (!drag) return; ev.stopPropagation(); state.undo.push(drag.before); state.redo = []; drag = null; };
  svg.addEventListener("pointerup", end, { capture: true });
  svg.addEventListener("pointercancel", end, { capture: true });

  return { update, box, notes: () => (rb.note ? [rb.note] : []) };
}
