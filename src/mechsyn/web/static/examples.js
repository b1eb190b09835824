// The Examples menu: grouped (planar first, then spatial; by folder within each) and a search box
// that narrows it (every word typed must appear in the name, title or folder; Enter opens the
// first example left).
import { h } from "./numeric.js";

// `list`: the server's [{name, title, group, kind}]; `open(name)` opens one.
export function fillExamples(select, search, list, open) {
  const groups = new Map();
  const sorted = list.slice().sort((a, b) => (a.kind === "planar" ? 0 : 1) - (b.kind === "planar" ? 0 : 1));
  for (const e of sorted) {
    const label = `${e.kind === "planar" ? "planar" : "spatial"} — ${e.group}`;
    if (!groups.has(label)) groups.set(label, h("optgroup", null, { label }));
    const o = h("option", `${e.name} — ${e.title}${e.kind === "planar" ? "" : ` (${e.kind})`}`, { value: e.name });
    o.dataset.words = `${e.name} ${e.title} ${e.group} ${e.kind}`.toLowerCase();
    groups.get(label).append(o);
  }
  select.append(...groups.values());
  if (!search) return;
  const visible = () => [...select.querySelectorAll("option[data-words]")].filter((o) => !o.hidden);
  search.oninput = () => {
    const words = search.value.toLowerCase().split(/\s+/).filter(Boolean);
    for (const o of select.querySelectorAll("option[data-words]")) o.hidden = !words.every((w) => o.dataset.words.includes(w));
    for (const g of select.querySelectorAll("optgroup")) g.hidden = ![...g.children].some((o) => !o.hidden);
    select.options[0].textContent = words.length ? `Examples (${visible().length} found)…` : "Examples…";
  };
  search.onkeydown = (ev) => {
    if (ev.key !== "Enter") return;
    const first = visible()[0];
    if (first) { open(first.value); search.blur(); }
  };
}
