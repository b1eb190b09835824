// Motion synthesis with choice (issue 40): the Burmester pivots of the result under the pointer
// drawn on the canvas as [data-burmester] elements (fixed pivots ▲, moving pivots ◯ with their
// positions at every pose and the circle each runs on, the linkage at pose 1; for 4 poses the
// centre-point and circle-point curves). For 3 poses a moving pivot is dragged or typed
// (inputs pivot-ax … pivot-by) and the linkage it gives is computed at once
// (POST /api/design/burmester: mechsyn.synthesis.motion_choice.linkage_from_pivots), offered
// with its label and an Apply button.
import { call } from "./api.js";
import { el, makeView } from "./draw.js";
import { h } from "./numeric.js";


// ctx: {$, state, render, setMech, setMode}
export function mountBurmester({ $, state, render, setMech, setMode }) {
  const fmt = (v) => String(+(+v).toPrecision(6));
  const svg = $("canvas");
  const box = h("div"); box.id = "burmester-box";
  $("synth-poses").after(box);
  const poseAngles = () => state.targets.map((_, i) => (state.targetAngles || [])[i] || 0);
  const motion = () => $("synth-kind").value === "motion";

  // the result whose pivots are drawn: the one under the pointer, else the one picked
  const shown = () => (motion() ? state.previewResult || null : null);

  state.overlays.burmester = (layer, v) => {
    const r = shown();
    if (!r || !r.pivots) return;
    const P = (p) => v.toScreen(p);
    if (state.motionCurves) {
      for (const [key, pts] of Object.entries(state.motionCurves)) {
        const d = pts.map((p) => { const [x, y] = P(p); return `M${x.toFixed(1)} ${y.toFixed(1)}h0.01`; }).join("");
        el("path", { d, class: `burmester-curve ${key}`, "data-burmester": `${key}-curve` }, layer);
      }
    }
    const [f0, f1] = r.pivots.fixed, moving = r.pivots.moving;
    const chain = [f0, moving[0][0], moving[1][0], f1].map(P);
    el("polyline", { points: chain.map((p) => p.map((c) => c.toFixed(1)).join(",")).join(" "), class: "burmester-linkage", "data-burmester": "linkage" }, layer);
    moving.forEach((pts, i) => {
      const c = P(r.pivots.fixed[i]), rad = Math.hypot(...[0, 1].map((k) => P(pts[0])[k] - c[k]));
      el("circle", { cx: c[0], cy: c[1], r: rad, class: "burmester-circle", "data-burmester": "circle" }, layer);
      pts.slice(1).forEach((p) => { const q = P(p); el("circle", { cx: q[0], cy: q[1], r: 3.5, class: "burmester-pos", "data-burmester": "position" }, layer); });
    });
    r.pivots.fixed.forEach((p, i) => {
      const [x, y] = P(p);
      el("path", { d: `M${x} ${y - 9}L${x + 8} ${y + 6}L${x - 8} ${y + 6}Z`, class: "burmester-fixed", "data-burmester": "fixed", "data-which": i }, layer);
    });
    moving.forEach((pts, i) => {
      const [x, y] = P(pts[0]);
      el("circle", { cx: x, cy: y, r: 8, class: "burmester-moving", "data-burmester": "moving", "data-which": i }, layer);
    });
  };

  // dragging a moving pivot (3 poses): the linkage follows, one request in flight
  let drag = null, busy = false, next = null;
  const world = (ev) => { const r = svg.getBoundingClientRect(); return makeView(svg, state.view).toWorld([ev.clientX - r.left, ev.clientY - r.top]); };
  svg.addEventListener("pointerdown", (ev) => {
    const t = ev.target.closest && ev.target.closest('[data-burmester="moving"]');
    if (!t || state.targets.length !== 3 || !shown()) return;
    ev.stopPropagation(); ev.preventDefault();
    drag = { which: +t.dataset.which };
    svg.setPointerCapture(ev.pointerId);
  }, { capture: true });
  svg.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    ev.stopPropagation();
    const pv = currentPivots(); pv[drag.which] = world(ev);
    pick(pv);
  }, { capture: true });
  const end = (ev) => { if (drag) { ev.stopPropagation(); drag = null; } };
  svg.addEventListener("pointerup", end, { capture: true });
  svg.addEventListener("pointercancel", end, { capture: true });

  function currentPivots() { const r = shown(); return r.pivots.moving.map((pts) => pts[0].slice()); }

  async function pick(pivots) {
    if (busy) { next = pivots; return; }
    busy = true;
    try {
      const out = await call("/api/design/burmester", { targets: state.targets, angles: poseAngles(), pivots });
      const r = out.results[0];
      r.custom = true;
      state.previewResult = r; state.preview = r.path;
      state.burmesterError = null;
    } catch (e) { state.burmesterError = e.error || String(e); }
    busy = false;
    render(); renderBox();
    if (next) { const n = next; next = null; pick(n); }
  }

  // the Synthesis tab's box: the moving pivots typed, the linkage they give and its Apply
  function renderBox() {
    const r = shown();
    if (!motion() || !r || !r.pivots || state.targets.length !== 3) { box.replaceChildren(); return; }
    const inputs = [];
    r.pivots.moving.forEach((pts, i) => ["x", "y"].forEach((c, k) => {
      const inp = h("input", null, { value: fmt(pts[0][k]), size: 6, name: `pivot-${"ab"[i]}${c}` });
      inp.onchange = () => { const v = Number(inp.value); if (!Number.isFinite(v)) return; const pv = currentPivots(); pv[i][k] = v; pick(pv); };
      inputs.push(h("label", ` ${"AB"[i]} ${c} `), inp);
    }));
    const p = h("p"); p.append("Moving pivots at pose 1:", ...inputs);
    const out = [h("h4", "Pick the moving pivots (drag ◯ on the canvas, or type them)"), p];
    if (state.burmesterError) out.push(h("p", state.burmesterError, { className: "err" }));
    else {
      const li = h("p", `${r.custom ? "your linkage: " : "shown: "}${r.label} `, { className: "quality" });
      if (r.mechanism) {
        const b = h("button", "Apply"); b.dataset.apply = "custom";
        b.onclick = () => apply(r);
        li.append(b);
      }
      out.push(li);
    }
    box.replaceChildren(...out);
  }

  function apply(r) {
    state.preview = null; state.previewResult = null; state.fileName = "";
    setMech(r.mechanism, { fit: true });
    setMode("select");
  }

  return { renderBox, apply, setCurves: (c) => { state.motionCurves = c || null; } };
}
