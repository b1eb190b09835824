// Dimensions as design variables (issue 40): a selected link's length (a bar), sides (a plate)
// and, for a slider's guide, its offset and angle, typed in the Element tab. The library
// re-assembles the mechanism on the drawn branch keeping every other dimension
// (POST /api/design/dimension: mechsyn.kinematics.dimensions); where it cannot assemble, the
// banner says which dimension breaks which condition and nothing changes.
import { call } from "./api.js";
import { h } from "./numeric.js";

const DIMENSION_INPUTS = { length: "length", side: "side", offset: "offset", angle: "guide-angle" };

// ctx: {$, state, render, setMech, rebase, renderElement}; returns {linkElement, setLength}.
export function mountDimensions({ state, render, setMech, rebase }) {
  const fmt = (v) => String(+(+v).toPrecision(8));
  // One typed dimension: one edit (one undo step) or, refused, the reason in the banner.
  async function change(c) {
    const mech = rebase();
    try {
      const out = await call("/api/design/dimension", { mechanism: mech, change: c });
      state.designNotes = { mech: out.mechanism, notes: out.notes || [] };
      setMech(out.mechanism);
    } catch (e) {
      state.frame = state.home;
      state.errors = [{ message: e.error || String(e), hint: e.hint, element: { kind: "link", id: c.link } }];
      render();
    }
  }

  // The Element tab of link `name`: its dimensions as number inputs (a request for the list).
  function linkElement(box, m, name) {
    const head = h("h3", `Link ${name}`);
    const note = h("p", "Type a dimension: the mechanism re-assembles on the drawn branch, every other dimension kept.", { className: "muted" });
    box.replaceChildren(head, note);
    call("/api/design/dimensions", { mechanism: m }).then((r) => {
      if (state.mech !== m || !state.selected || state.selected.id !== name) return;
      const rows = r.dimensions.filter((d) => d.link === name);
      if (!rows.length) rows.push(null);
      box.replaceChildren(head, note, ...rows.map((d) => (d ? row(d) : h("p", "no dimension to type on this link", { className: "muted" }))));
    }, (e) => box.append(h("p", e.error || String(e), { className: "err" })));
  }

  function row(d) {
    const label = d.kind === "length" ? `length ${d.joints.join("–")}` : d.kind === "side" ? `side ${d.joints.join("–")}`
      : d.kind === "offset" ? `guide offset of ${d.joints[0]} from ${d.joints[1]}` : `guide angle of ${d.joints[0]} (°)`;
    const inp = h("input", null, { type: "text", inputMode: "decimal", value: fmt(d.value), name: DIMENSION_INPUTS[d.kind], size: 10 });
    inp.dataset.joints = d.joints.join(",");
    inp.onchange = () => {
      const v = Number(inp.value.trim().replace(",", "."));
      if (inp.value.trim() === "" || !Number.isFinite(v)) { inp.setCustomValidity("a number"); inp.reportValidity(); return; }
      change({ link: d.link, kind: d.kind, joints: d.joints, value: v });
    };
    const p = h("p"); p.append(h("label", label + " "), inp);
    return p;
  }

  // A slider's (P joint's) guide: its offset and angle as design variables, in the joint's Element tab.
  function guideRows(m, jid) {
    const box = h("div"); box.className = "guide-dimensions";
    call("/api/design/dimensions", { mechanism: m }).then((r) => {
      if (state.mech !== m) return;
      const rows = r.dimensions.filter((d) => (d.kind === "offset" || d.kind === "angle") && d.joints[0] === jid);
      if (rows.length) box.replaceChildren(h("h4", "Guide (re-assembled, the other dimensions kept)"), ...rows.map(row));
    }, () => {});
    return box;
  }

  // The Joints tab's bar lengths go the same way.
  const setLength = (link, v) => change({ link, kind: "length", value: v });
  return { linkElement, setLength, guideRows };
}
