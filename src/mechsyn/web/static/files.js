// Work kept in the browser: the edited mechanism autosaved to localStorage on every edit, offered
// back when the page is opened again, and a prompt before leaving the page with unsaved work.
const KEY = "mechsyn-studio:autosave";

export function autosave(mech, name) {
  try { localStorage.setItem(KEY, JSON.stringify({ mechanism: mech, name, saved: new Date().toISOString() })); } catch (e) { /* storage full or off: nothing kept */ }
}
export function savedWork() {
  try { const w = JSON.parse(localStorage.getItem(KEY) || "null"); return w && w.mechanism && w.mechanism.joints ? w : null; } catch (e) { return null; }
}
export function forgetWork() { try { localStorage.removeItem(KEY); } catch (e) { /* nothing kept */ } }

// Ask before the page is left while `dirty()` says there is unsaved work.
export function guardUnload(dirty) {
  window.addEventListener("beforeunload", (ev) => { if (dirty()) { ev.preventDefault(); ev.returnValue = ""; } });
}

// An error answer as one line: the field it names, the message, the fix.
export function errorText(e, prefix = "") {
  if (!e || typeof e !== "object") return prefix + String(e);
  return prefix + (e.field && !["mechanism", "body"].includes(e.field) ? `${e.field}: ` : "") + (e.error || e.message || String(e)) + (e.hint ? ` — fix: ${e.hint}` : "");
}
