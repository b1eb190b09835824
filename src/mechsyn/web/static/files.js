// Files: opening (examples, the start directory, uploads), saving, exporting; and work kept in the
// browser: the edited mechanism autosaved to localStorage on every edit, offered back when the
// page is opened again, and a prompt before leaving the page with unsaved work.
import { call } from "./api.js";
import { h } from "./numeric.js";
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

// Why the studio could not start, in words that say how to open it: the page without its token,
// or with the token of a server that was restarted since (a reloaded old tab).
export function startProblem(e) {
  if (e && e.field === "token") {
    const has = new URLSearchParams(location.search).get("token");
    return has ? "this tab's token is stale: the studio server was restarted since the tab was opened. Open the new URL that "
      + "`mechsyn serve` printed in its terminal (it ends with ?token=…); edits autosaved in this browser are offered again when it opens at the same address"
      : "this page was opened without its token. Open the URL that `mechsyn serve` printed in its terminal (it ends with ?token=…), "
      + "or start the studio with `mechsyn serve`";
  }
  return errorText(e);
}

// An error answer as one line: the field it names, the message, the fix.
export function errorText(e, prefix = "") {
  if (!e || typeof e !== "object") return prefix + String(e);
  return prefix + (e.field && !["mechanism", "body"].includes(e.field) ? `${e.field}: ` : "") + (e.error || e.message || String(e)) + (e.hint ? ` — fix: ${e.hint}` : "");
}

// The Files controls of the toolbar. `ctx`: {$, svg, state, render, setMech, fitView};
// returns {openFrom(promise, from), refreshFiles()}.
export function mountFiles({ $, svg, state, render, setMech, fitView }) {
  async function openFrom(promise, from = "") {
    try {
      const r = await promise;
      state.fileName = r.name || "";
      $("save-name").value = state.fileName.includes("/") || !state.fileName ? state.fileName : state.fileName;
      state.selected = null;
      setMech(r.mechanism, { fit: true, opened: true });
      // fit again once the paths are known
      const n = state.simulations;
      const wait = () => (state.simulations > n ? (fitView(), render()) : setTimeout(wait, 30));
      wait();
    } catch (e) {
      state.errors = [{ message: errorText(e, from ? `${from}: ` : "") }]; render();
    }
  }

  $("examples").onchange = (ev) => { if (ev.target.value) openFrom(call(`/api/examples/${encodeURIComponent(ev.target.value)}`)); ev.target.value = ""; };
  $("files").onfocus = refreshFiles;
  $("files").onchange = (ev) => { if (ev.target.value) openFrom(call(`/api/file?path=${encodeURIComponent(ev.target.value)}`)); ev.target.value = ""; };
  $("upload").onchange = async (ev) => {
    const f = ev.target.files[0];
    if (!f) return;
    openFrom(call("/api/import", { text: await f.text(), filename: f.name }), f.name);
    ev.target.value = "";
  };
  $("save").onclick = async () => {
    const name = $("save-name").value.trim() || "mechanism.yaml";
    try {
      let r;
      try { r = await call("/api/file", { path: name, mechanism: state.mech }); }
      catch (e) {
        if (!/exists/.test(e.error || "") || !confirm(`${name} exists: overwrite it?`)) throw e;
        r = await call("/api/file", { path: name, mechanism: state.mech, overwrite: true });
      }
      state.notes = [`saved ${r.saved} (${r.bytes} bytes)`]; state.fileName = r.saved; state.dirty = false; render(); refreshFiles();
    } catch (e) { state.errors = [{ message: `not saved: ${e.error || e}`, hint: e.hint }]; render(); }
  };

  function download(name, blob) {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob); a.download = name;
    document.body.append(a); a.click(); a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 5000);
  }
  async function svgText() {
    const css = await fetch("/static/studio.css").then((r) => r.text());
    const c = svg.cloneNode(true);
    c.setAttribute("xmlns", "http://www.w3.org/2000/svg");
    const style = document.createElementNS("http://www.w3.org/2000/svg", "style");
    style.textContent = css;
    c.insertBefore(style, c.firstChild);
    const bg = document.createElementNS("http://www.w3.org/2000/svg", "rect");
    bg.setAttribute("width", "100%"); bg.setAttribute("height", "100%"); bg.setAttribute("fill", "#fff");
    c.insertBefore(bg, style.nextSibling);
    return new XMLSerializer().serializeToString(c);
  }
  const base = () => (state.fileName || state.mech.name || "mechanism").replace(/\.[a-z]+$/i, "").replace(/[^\w.-]+/g, "_");
  $("export").onchange = async (ev) => {
    const fmt = ev.target.value; ev.target.value = "";
    if (!fmt || !state.mech) return;
    try {
      if (fmt === "svg") download(`${base()}.svg`, new Blob([await svgText()], { type: "image/svg+xml" }));
      else if (fmt === "drawing" || fmt === "dxf") { // the library's drawing in model units / plates to cut
        const text = await call(`/api/studio/${fmt}`, { mechanism: state.mech }, { raw: true });
        download(`${base()}${fmt === "dxf" ? "_plates.dxf" : "_drawing.svg"}`, new Blob([text], { type: fmt === "dxf" ? "application/dxf" : "image/svg+xml" }));
      }
      else if (fmt === "png") {
        const url = URL.createObjectURL(new Blob([await svgText()], { type: "image/svg+xml" }));
        const img = new Image();
        await new Promise((ok, bad) => { img.onload = ok; img.onerror = bad; img.src = url; });
        const r = svg.getBoundingClientRect(), cv = document.createElement("canvas");
        cv.width = r.width * 2; cv.height = r.height * 2;
        const ctx = cv.getContext("2d"); ctx.scale(2, 2); ctx.drawImage(img, 0, 0, r.width, r.height);
        URL.revokeObjectURL(url);
        cv.toBlob((b) => download(`${base()}.png`, b), "image/png");
      } else if (fmt === "gif") {
        state.notes = ["making the animation…"]; render();
        download(`${base()}.gif`, await call("/api/export", { mechanism: state.mech, format: "gif" }, { blob: true }));
        state.notes = []; render();
      } else {
        const text = await call("/api/export", { mechanism: state.mech, format: fmt }, { raw: true });
        download(`${base()}.${fmt}`, new Blob([text], { type: "text/plain" }));
      }
    } catch (e) { state.errors = [{ message: errorText(e, "export failed: ") }]; render(); }
  };

  async function refreshFiles() {
    try {
      const { files } = await call("/api/files");
      const keep = $("files").value;
      $("files").replaceChildren(h("option", "Files…", { value: "" }), ...files.map((f) => h("option", f, { value: f })));
      $("files").value = keep;
    } catch (e) { /* the list stays as it was */ }
  }
  return { openFrom, refreshFiles };
}
