"""The web app ``jt ui`` serves: MLflow's own server app, whose page first sets a few of MLflow's
browser-side preferences, each only where the browser holds none of its own yet.

MLflow 3 keeps a visitor's choices in the browser's ``localStorage``: whether the UI shows GenAI's
view or "Model training" (``mlflow.workflowType``, GenAI until the user flips the switch), whether
its assistant panel has been opened once already (it opens by itself on a first visit to a local
server), whether its telemetry notice was dismissed. A ``?workflowType=`` in a URL holds only for
that page: a click into a run lands in GenAI's view again. So the page ``/`` gets a short script,
run before MLflow's own, that sets

- ``mlflow.workflowType`` to ``machine_learning``: jt's runs are model training;
- the assistant's "opened on first load" mark: its panel opens from its button only;
- the telemetry notice dismissed: ``jt ui`` starts the server with telemetry off.

A user's own choice (the switch flipped to GenAI, the panel opened) stands: nothing is set where a
value exists. MLflow's ``mlflow ui --app-name jt-ui`` starts it (the ``mlflow.app`` entry point of
jt's package), which is how MLflow runs other apps around its server (``basic-auth``).
"""

from __future__ import annotations

import importlib
import json
from typing import Any, Callable, Optional

DEFAULTS = {
    "mlflow.workflowType_v1": json.dumps("machine_learning"),
    "mlflow.assistant.fab.autoOpenedOnFirstLoad_v1": "true",
    "mlflow.telemetry.info.alert.dismissed_v1": "true",
}
"""``localStorage`` key -> value (as MLflow 3.17's UI writes them: ``<key>_v<version>``, JSON)."""

SNIPPET = ("<script data-jt=\"defaults\">(function(){try{var d=" + json.dumps(DEFAULTS) + ";for(var k in d)"
           "{if(window.localStorage.getItem(k)===null){window.localStorage.setItem(k,d[k]);}}}catch(e){}})();"
           "</script>").encode()

#: request headers dropped on the way to MLflow for the page: the whole page, uncompressed, every time
_DROP_REQUEST = {b"accept-encoding", b"if-none-match", b"if-modified-since", b"range"}
#: response headers of the page that no longer hold once the script is in
_DROP_RESPONSE = {b"content-length", b"etag", b"last-modified", b"cache-control"}


def inject(html: bytes) -> bytes:
    """``html`` with ``SNIPPET`` first in its ``<head>`` (as it is where there is no ``<head>``)."""
    at = html.find(b"<head>")
    if at < 0:
        return html
    at += len(b"<head>")
    return html[:at] + SNIPPET + html[at:]


def _header(headers: list, name: bytes) -> bytes:
    return next((v for k, v in headers if k.lower() == name), b"")


class DefaultsApp:
    """An ASGI app: ``inner`` (loaded on first use) with ``SNIPPET`` put into the page at ``/``.

    Args:
        load: returns the inner ASGI app (MLflow's, imported in the server process only).
    """

    def __init__(self, load: Callable[[], Any]) -> None:
        self._load = load
        self._inner: Optional[Any] = None

    @property
    def inner(self) -> Any:
        if self._inner is None:
            self._inner = self._load()
        return self._inner

    async def __call__(self, scope: dict, receive: Callable, send: Callable) -> None:
        inner = self.inner
        if scope.get("type") != "http" or scope.get("method") != "GET" or scope.get("path") != "/":
            await inner(scope, receive, send)
            return
        scope = {**scope, "headers": [(k, v) for k, v in scope.get("headers", []) if k.lower() not in _DROP_REQUEST]}
        start: dict = {}
        chunks: list[bytes] = []

        async def capture(message: dict) -> None:
            if message["type"] == "http.response.start":
                start.update(message)
                return
            if message["type"] != "http.response.body":
                await send(message)
                return
            chunks.append(message.get("body", b""))
            if message.get("more_body", False):
                return
            body, headers = b"".join(chunks), list(start.get("headers", []))
            if (start.get("status") == 200 and _header(headers, b"content-type").startswith(b"text/html")
                    and not _header(headers, b"content-encoding")):
                body = inject(body)
                headers = [(k, v) for k, v in headers if k.lower() not in _DROP_RESPONSE]
                headers += [(b"content-length", str(len(body)).encode()), (b"cache-control", b"no-cache")]
            await send({**start, "headers": headers})
            await send({"type": "http.response.body", "body": body})

        await inner(scope, receive, capture)


app = DefaultsApp(lambda: importlib.import_module("mlflow.server.fastapi_app").app)
"""What ``mlflow ui --app-name jt-ui`` serves (uvicorn imports it by name)."""
