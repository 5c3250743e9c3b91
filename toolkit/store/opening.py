"""Open the store a user names with ``store=``: a local folder or an MLflow tracking server.

``open_store`` is the one place that tells the two apart, so ``Store`` (a local SQLite store)
and ``ServerStore`` (its subclass over HTTP) need not know each other's module.
"""

from __future__ import annotations

import os

from toolkit.store.tracking import Store, is_server_uri


def open_store(root: str | os.PathLike, must_exist: bool = False) -> Store:
    """The store at ``root``: a ``ServerStore`` for ``http(s)://host:port``, else a local ``Store``.

    Args:
        root: a store folder or an MLflow server URI (what ``store=`` / ``JT_STORE`` hold).
        must_exist: refuse (one ``JtError`` line) instead of creating a local store that is
            not there; a server must answer either way.
    """
    if is_server_uri(str(root)):
        from toolkit.store.server import ServerStore

        return ServerStore(root, must_exist)
    return Store(root, must_exist)
