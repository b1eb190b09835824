"""mechsyn studio in a Jupyter cell: an anywidget running the studio's own front end.

The widget's JavaScript is the studio's (``static/*.js``, joined into one module, the
``import``/``export`` lines between them removed) mounted on the cell's element. Its
requests travel as widget messages to the kernel, where they are answered by the very
same app as ``mechsyn serve`` (:func:`mechsyn.web.create_app`, called in-process), so
the notebook and the browser app give the same answers. Every edit is synced back to
:attr:`MechanismWidget.value` (the file-format dict) and :attr:`MechanismWidget.mechanism`.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.web.widget import MechanismWidget
>>> w = MechanismWidget(ms.load("fourbar"))  # the last line of a cell shows the editor
>>> w.mechanism.name
'Four-bar linkage'
"""

from __future__ import annotations

import json
import re
import secrets
import warnings
from pathlib import Path
from typing import Any

from mechsyn._extras import require

anywidget = require("anywidget", "Mechanism.widget()", "notebook")
require("httpx", "Mechanism.widget()", "notebook")  # the in-process app answers through starlette's TestClient
import traitlets  # noqa: E402  (installed with anywidget)

STATIC = Path(__file__).parent / "static"
MODULES = ("vendor/uPlot.esm.js", "api.js", "draw.js", "checks.js", "numeric.js", "keys.js", "files.js", "player.js",
           "synthesis.js", "atlas.js", "plots.js", "analysis.js", "examples.js", "forces.js", "view3d.js", "tabs3d.js",
           "dimensions.js", "burmester.js", "robot.js", "centres.js", "design.js",
           "studio.js")  # view3d.js, tabs3d.js: spatial files; uPlot: the charts (plots.js); design.js mounts its four


def _body_markup() -> str:
    html = (STATIC / "index.html").read_text(encoding="utf-8")
    return html[html.index("<body>") + len("<body>"):html.index("</body>")]


def widget_esm() -> str:
    """The studio's modules as one ES module whose default export renders the widget."""
    parts = []
    for name in MODULES:
        text = (STATIC / name).read_text(encoding="utf-8")
        text = re.sub(r"^import .*? from \"\./[A-Za-z0-9/.]+\.js\";.*\n", "", text, flags=re.M)  # view3d: digits, comments
        text = text.replace("export { uPlot as default };", "")  # the vendored uPlot: its class is in scope
        parts.append(f"// ---- {name}\n{text}")
    render = """
// ---- the widget: the studio's markup in the cell, requests as messages to the kernel
function kernelTransport(model) {
  let next = 0;
  const waiting = new Map();
  model.on("msg:custom", (msg) => {
    const w = waiting.get(msg.id);
    if (!w) return;
    waiting.delete(msg.id);
    if (msg.ok) w.ok(msg.data); else w.bad(msg.data);
  });
  return { events: false, request(path, method, body, raw) {
    const id = ++next;
    model.send({ id, path, method, body: body === undefined ? null : body, raw: !!raw });
    return new Promise((ok, bad) => waiting.set(id, { ok, bad }));
  } };
}
export default {
  render({ model, el }) {
    const root = document.createElement("div");
    root.className = "mechsyn-studio";
    root.tabIndex = 0;
    root.dataset.lmSuppressShortcuts = "true"; // JupyterLab (Lumino) leaves keys pressed here alone
    root.innerHTML = MARKUP;
    el.appendChild(root);
    useTransport(kernelTransport(model));
    mount(root, { onChange: (m) => { model.set("value", m); model.save_changes(); } });
  },
};
"""
    return "\n".join(parts) + f"\nconst MARKUP = {json.dumps(_body_markup())};\n" + render


def widget_css() -> str:
    """The studio's style sheet scoped to the widget: every selector prefixed with
    ``.mechsyn-studio`` (the page's html/body rules left out), so nothing of it reaches the
    notebook's own toolbar, buttons or inputs."""
    css = "\n".join((STATIC / name).read_text(encoding="utf-8") for name in ("vendor/uPlot.min.css", "studio.css"))
    css = re.sub(r"/\*.*?\*/", "", css, flags=re.S)
    rules = []
    for selectors, body in re.findall(r"([^{}]+)\{([^}]*)\}", css):
        sels = [x.strip() for x in selectors.split(",") if x.strip() not in ("html", "body", "")]
        if sels:
            rules.append(", ".join(f".mechsyn-studio {x}" for x in sels) + " {" + body + "}")
    return "\n".join(rules) + ("\n.mechsyn-studio { display: grid; grid-template-rows: auto 1fr auto; height: 640px; "
                              "font: 13px system-ui, sans-serif; color: #222; background: #fafafa; border: 1px solid #ccd; }\n")


class MechanismWidget(anywidget.AnyWidget):
    """The studio editor on one mechanism; :attr:`value` follows every edit.

    Parameters
    ----------
    mechanism
        A :class:`~mechsyn.model.mechanism.Mechanism`, or a mechanism file dict.
    root
        The directory the widget may read and save files in (default: the working one).
    """

    _esm = traitlets.Unicode(widget_esm()).tag(sync=True)
    _css = traitlets.Unicode(widget_css()).tag(sync=True)
    value = traitlets.Dict().tag(sync=True)

    def __init__(self, mechanism: Any = None, root: str | Path = ".", **kwargs: Any) -> None:
        with warnings.catch_warnings():  # starlette's notice about its httpx client, shown in every cell
            warnings.filterwarnings("ignore", message=".*starlette.testclient.*")
            from starlette.testclient import TestClient

        from mechsyn.io import mechanism_to_dict
        from mechsyn.web import create_app

        start = mechanism if isinstance(mechanism, dict) or mechanism is None else mechanism_to_dict(mechanism)
        super().__init__(value=start or {}, **kwargs)
        token = secrets.token_urlsafe(16)
        self._app = create_app(root, start=start, token=token)
        self._client = TestClient(self._app, base_url="http://127.0.0.1", headers={"X-Mechsyn-Token": token})
        self.on_msg(self._on_request)

    @property
    def mechanism(self):
        """The edited mechanism as a :class:`~mechsyn.model.mechanism.Mechanism` (validated)."""
        from mechsyn.io import mechanism_from_dict

        return mechanism_from_dict(self.value, source="widget")

    def answer(self, request: dict[str, Any]) -> dict[str, Any]:
        """The studio app's answer to one front-end request ``{id, path, method, body, raw}``."""
        path, method = str(request.get("path", "")), str(request.get("method", "GET"))
        if not path.startswith("/api/"):
            return {"id": request.get("id"), "ok": False, "data": {"error": f"not an API path: {path}"}}
        resp = self._client.request(method, path, json=request.get("body") if method != "GET" else None)
        ok = resp.status_code < 400
        if ok and request.get("raw"):
            data: Any = resp.text
        else:
            try:
                data = resp.json()
            except ValueError:
                data = {"error": f"HTTP {resp.status_code}"}
        return {"id": request.get("id"), "ok": ok, "data": data}

    def _on_request(self, widget: Any, content: dict, buffers: list) -> None:
        self.send(self.answer(content))
