// The studio's keyboard: shortcuts that work after any control was used, Delete/Backspace on the
// selection, and (in a notebook widget) key events kept inside the studio.

// Controls where keys are typed: shortcuts wait until they are left.
const TYPING = "input:not([type=checkbox]):not([type=radio]):not([type=range]):not([type=button]):not([type=file]), textarea";

// `actions`: {undo, redo, finishLink, escape, play, fit, deleteSelection, setMode, linkMode(), step(±1)}.
// `contained`: the studio is part of a bigger page (a notebook): its key events stop at `root`.
export function bindKeys(root, actions, { contained = false } = {}) {
  const target = root.addEventListener ? root : document;
  // a select, checkbox or slider keeps the focus after a change: give it back to the page, so the
  // next key is a shortcut again (a select would otherwise take the letters as choices)
  target.addEventListener("change", (ev) => {
    if (ev.target.matches && ev.target.matches("select, input[type=checkbox], input[type=range], input[type=file]")) ev.target.blur();
  });
  target.addEventListener("keydown", (ev) => {
    if (contained) ev.stopPropagation();
    if (ev.target.matches && (ev.target.matches(TYPING) || (ev.target.matches("select") && !ev.ctrlKey && !ev.metaKey))) return;
    const k = ev.key;
    if ((ev.ctrlKey || ev.metaKey) && k === "z") { ev.preventDefault(); actions.undo(); }
    else if ((ev.ctrlKey || ev.metaKey) && (k === "y" || k === "Z")) { ev.preventDefault(); actions.redo(); }
    else if (k === "Enter" && actions.linkMode()) actions.finishLink();
    else if (k === "Escape") actions.escape();
    else if (k === " ") { ev.preventDefault(); actions.play(); }
    else if (k === "Delete" || k === "Backspace") { ev.preventDefault(); actions.deleteSelection(); }
    else if ((k === "ArrowRight" || k === "ArrowLeft") && actions.step) { ev.preventDefault(); actions.step(k === "ArrowRight" ? 1 : -1); }
    else if (!ev.ctrlKey && !ev.metaKey && !ev.altKey) {
      const mode = { v: "select", g: "pivot", l: "link", p: "point", d: "drive", x: "delete", t: "target" }[k.toLowerCase()];
      if (mode) actions.setMode(mode);
      if (k === "f") actions.fit();
    }
  });
  if (contained) for (const type of ["keyup", "keypress"]) target.addEventListener(type, (ev) => ev.stopPropagation());
}
