// The Atlas tab: the non-isomorphic chains of a number of links and mobility, drawn; Open puts one
// on the canvas.
import { call } from "./api.js";
import { el } from "./draw.js";
import { h } from "./numeric.js";

// `ctx`: {$, state, render, setMech}.
export function mountAtlas({ $, state, render, setMech }) {
  $("atlas-go").onclick = async () => {
    $("atlas").replaceChildren(h("p", "listing…", { className: "muted" }));
    try {
      const { chains } = await call(`/api/atlas?links=${$("atlas-links").value}&mobility=${$("atlas-mobility").value}`);
      $("atlas").replaceChildren(...chains.map(chainFigure));
      if (!chains.length) $("atlas").replaceChildren(h("p", "no chains", { className: "muted" }));
    } catch (e) { $("atlas").replaceChildren(h("p", e.error || String(e), { className: "err" })); }
  };

  function chainFigure(c) {
    const fig = h("figure");
    const s = el("svg", { viewBox: "-70 -70 140 140", "data-chain": c.index });
    const jx = c.joint_xy, xs = jx.map((p) => p[0]), ys = jx.map((p) => p[1]);
    const cx = (Math.min(...xs) + Math.max(...xs)) / 2, cy = (Math.min(...ys) + Math.max(...ys)) / 2;
    const sc = 110 / Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys), 1e-9);
    const P = (p) => [(p[0] - cx) * sc, -(p[1] - cy) * sc];
    const frame = c.mechanisms.length ? c.mechanisms[0].frame : 0;
    for (let l = 0; l < c.chain.n_links; l++) {
      const pts = c.chain.edges.map((e, k) => (e.includes(l) ? P(jx[k]) : null)).filter(Boolean);
      if (pts.length === 2) {
        const bar = el("line", { x1: pts[0][0], y1: pts[0][1], x2: pts[1][0], y2: pts[1][1], class: "link-bar", "stroke-width": 3 }, s);
        if (l === frame) bar.style.stroke = "#999"; // the frame grey (a class rule beats an attribute)
      } else {
        const cxy = pts.reduce((a, p) => [a[0] + p[0] / pts.length, a[1] + p[1] / pts.length], [0, 0]);
        pts.sort((a, b) => Math.atan2(a[1] - cxy[1], a[0] - cxy[0]) - Math.atan2(b[1] - cxy[1], b[0] - cxy[0]));
        const plate = el("polygon", { points: pts.map((p) => p.join(",")).join(" "), class: "link-plate" }, s);
        if (l === frame) plate.style.fill = "#ccc";
      }
    }
    for (const p of jx.map(P)) el("circle", { cx: p[0], cy: p[1], r: 3, class: "joint" }, s);
    fig.append(s, h("figcaption", `#${c.index + 1} ${c.label}`));
    const b = h("button", "Open"); b.dataset.openChain = c.index;
    b.onclick = async () => {
      try {
        const ch = c.mechanisms[0] || {};
        const r = await call("/api/atlas/mechanism", { chain: c.chain, frame: ch.frame, input: ch.input });
        state.fileName = ""; setMech(r.mechanism, { fit: true });
      } catch (e) { state.errors = [{ message: e.error }]; render(); }
    };
    fig.append(b);
    return fig;
  }
}
