"""MLflow tracking for jt: one SQLite store per root, buffered metrics, explicit run ids.

Everything goes through ``MlflowClient`` with explicit run ids (never MLflow's global "active
run"), so a driver can keep an outer run and many nested evaluation runs open at once, and two jt
processes can share a store. Creating a fresh store is serialised with a lock file, because two
processes running MLflow's schema migrations on the same new database at once would collide.

A store may also be an MLflow tracking server, ``store=http://host:port``: ``Store(uri)`` then
returns a ``toolkit.store.server.ServerStore``, which logs and reads artifacts through the server
and keeps working folders in a local cache.
"""

from __future__ import annotations

import fcntl
import logging
import os
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Mapping, Optional

from toolkit.errors import JtError

MAX_PARAMS_PER_BATCH = 100
MAX_METRICS_PER_BATCH = 1000


def is_server_uri(ref: Any) -> bool:
    """Whether ``ref`` names an MLflow tracking server (``http://`` or ``https://``)."""
    return isinstance(ref, str) and ref.lower().startswith(("http://", "https://"))


def store_root(path: Optional[str | os.PathLike] = None) -> Path | str:
    """The store ``path``, else ``$JT_STORE``, else ``./artifacts``: an absolute folder, or a
    server URI as it is (without a trailing ``/``)."""
    ref = path or os.environ.get("JT_STORE") or "artifacts"
    if is_server_uri(str(ref)):
        return str(ref).rstrip("/")
    return Path(ref).expanduser().resolve()


def quiet_mlflow_logs() -> None:
    """MLflow's and its database's INFO lines off, and MLflow's tracebacks of database errors it then
    raises anyway (call after importing mlflow: it sets its own levels)."""
    for name in ("alembic", "mlflow", "sqlalchemy"):
        logging.getLogger(name).setLevel(logging.WARNING)
    logging.getLogger("mlflow.store.db.utils").setLevel(logging.CRITICAL)


SQLITE_MAGIC = b"SQLite format 3\x00"
"""The first 16 bytes of every SQLite database file."""


def check_root(root: Path, must_exist: bool = False) -> None:
    """One ``JtError`` line when ``root`` cannot be a store: a file, a folder whose ``mlflow.db`` is
    not SQLite (corrupt, truncated, another file), or (``must_exist``) no store at all.

    Args:
        root: the store folder.
        must_exist: refuse a folder without ``mlflow.db`` (reading commands never create a store).
    """
    _check_length(root)
    if root.exists() and not root.is_dir():
        raise JtError(f"store={root} is a file, not a folder; give a folder (created if missing) "
                      "or an MLflow server URI http://host:port")
    db = root / "mlflow.db"
    if must_exist and not db.is_file():
        raise JtError(f"no jt store at {root} (no mlflow.db); jt run ... store={root} makes one")
    if db.is_file() and db.stat().st_size > 0:
        with open(db, "rb") as fh:
            head = fh.read(len(SQLITE_MAGIC))
        if head != SQLITE_MAGIC:
            raise JtError(f"store={root}: its mlflow.db is not an SQLite database (corrupt, or another "
                          "file); move it away to start a new store there, or give another store=")


INNER_PATH_BYTES = 300  #: room for what jt keeps under a store (runs/<experiment>/<run id>/artifacts/...)


def _check_length(root: Path) -> None:
    """One ``JtError`` line for a store path the file system cannot hold: a folder name over its
    name limit, or a path that leaves no room for the files jt keeps under it."""
    probe = root
    while probe != probe.parent:
        try:
            if probe.exists():
                break
        except OSError:  # ENAMETOOLONG: a part over the limit, said below
            pass
        probe = probe.parent
    try:
        name_max, path_max = os.pathconf(probe, "PC_NAME_MAX"), os.pathconf(probe, "PC_PATH_MAX")
    except (OSError, ValueError):
        name_max, path_max = 255, 4096
    for part in root.parts:
        if len(part.encode()) > name_max:
            raise JtError(f"store=...{part[-30:]}: a folder name of {len(part.encode())} bytes; the file system takes "
                          f"{name_max} at most: give a shorter store=")
    if len(str(root).encode()) + INNER_PATH_BYTES > path_max:
        raise JtError(f"store=...{str(root)[-30:]}: a path of {len(str(root).encode())} bytes leaves no room for the "
                      f"files jt keeps under it ({INNER_PATH_BYTES} more; the file system takes {path_max}): give a "
                      "shorter store=")


@contextmanager
def _locked(root: Path) -> Iterator[None]:
    root.mkdir(parents=True, exist_ok=True)
    with open(root / ".jt.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


class Store:
    """A jt store: ``<root>/mlflow.db`` for tracking, ``<root>/runs/<experiment>/<run>/artifacts``
    for artifacts, ``<root>/work/<run>/`` for evaluation working folders (checkpoints).

    Args:
        root: store directory (created if missing); a store given as ``store=`` (a folder or an
            MLflow server URI, ``http://host:port``) is opened with ``toolkit.store.opening.open_store``.
    """

    is_server = False
    """Whether the store is an MLflow tracking server (``toolkit.store.server.ServerStore``)."""

    def __init__(self, root: str | os.PathLike, must_exist: bool = False) -> None:
        if is_server_uri(str(root)):  # never a local folder named after a URL
            raise ValueError(f"{root} is a server URI: open it with toolkit.store.opening.open_store")
        self.root = Path(root).resolve()
        self.uri = f"sqlite:///{self.root / 'mlflow.db'}"
        check_root(self.root, must_exist)
        from mlflow.tracking import MlflowClient

        quiet_mlflow_logs()

        try:
            with _locked(self.root):
                self._open_database(MlflowClient)
        except OSError as e:
            raise JtError(f"store={self.root}: cannot write there ({e.strerror or e}); "
                          "give a folder you can write to, or an MLflow server URI http://host:port") from e
        except Exception as e:  # noqa: BLE001 - MLflow / SQLAlchemy raise many types for a bad database
            if any(m in type(e).__module__.lower() for m in ("sqlite", "sqlalchemy", "alembic")) \
                    or "MlflowException" in type(e).__name__:
                raise JtError(f"store={self.root}: its mlflow.db is not a usable MLflow database "
                              f"({str(e).splitlines()[0][:120]}); move it away to start a new store "
                              "there, or give another store=") from e
            raise

    def _open_database(self, client_class: Any) -> None:
        """Under the store's lock: build a new database where no signal can leave it half-built
        (``toolkit.store.creation``), rebuild one that an interrupted first run left half-migrated
        (it holds no run), and open the client."""
        from toolkit.store import creation

        db = self.root / creation.DB
        creation.remove_partials(self.root)
        if creation.needs_building(db):
            creation.build(self.root, self._migrate)
        try:
            self.client = client_class(tracking_uri=self.uri)
            self.client.search_experiments(max_results=1)  # an older store's migrations, under the lock
        except Exception:  # noqa: BLE001 - MLflow / SQLAlchemy raise many types for a bad database
            if not creation.never_held_a_run(db):
                raise
            _dispose(self.uri)
            db.unlink()
            creation.build(self.root, self._migrate)
            self.client = client_class(tracking_uri=self.uri)
            self.client.search_experiments(max_results=1)
        self._default_inside(db)

    def _migrate(self, uri: str) -> None:
        """Create and migrate MLflow's schema in the database at ``uri``, point its Default
        experiment into the store, and release every connection to it."""
        from mlflow.tracking import MlflowClient

        MlflowClient(tracking_uri=uri).search_experiments(max_results=1)
        _dispose(uri)
        self._default_inside(Path(uri[len("sqlite:///"):]))

    def _default_inside(self, db: Path) -> None:
        """Point MLflow's "Default" experiment (id 0) into the store: MLflow creates it with the
        artifact location ``<cwd>/mlruns/0``, outside the store (and MLflow has no call to move it)."""
        import sqlite3

        inside = str(self.root / "runs" / "Default")
        con = sqlite3.connect(db, timeout=30)
        try:
            with con:
                con.execute("UPDATE experiments SET artifact_location = ? WHERE experiment_id = 0 "
                            "AND artifact_location != ?", (inside, inside))
        finally:
            con.close()

    # ---- experiments and runs ------------------------------------------------------------
    def experiment_id(self, name: str) -> str:
        """Id of experiment ``name``, created with its artifacts under ``<root>/runs/<name>``."""
        exp = self.client.get_experiment_by_name(name)
        if exp is not None:
            return exp.experiment_id
        location = str(self.root / "runs" / name)
        try:
            return self.client.create_experiment(name, artifact_location=location)
        except Exception:  # noqa: BLE001 - another process created it first
            exp = self.client.get_experiment_by_name(name)
            if exp is None:
                raise
            return exp.experiment_id

    def describe_experiment(self, name: str, description: str, tags: Optional[Mapping[str, str]] = None) -> str:
        """Give experiment ``name`` (created if missing) a markdown description (MLflow's
        ``mlflow.note.content``, shown on its page) and tags, unless it has them; returns its id."""
        eid = self.experiment_id(name)
        have = self.client.get_experiment(eid).tags
        for key, value in {"mlflow.note.content": description, **(tags or {})}.items():
            if key not in have:
                self.client.set_experiment_tag(eid, key, str(value))
        return eid

    def start_run(
        self,
        experiment: str,
        run_name: Optional[str] = None,
        tags: Optional[Mapping[str, str]] = None,
        parent_run_id: Optional[str] = None,
    ) -> str:
        """Create a RUNNING run; returns its id."""
        tags = dict(tags or {})
        if parent_run_id:
            tags["mlflow.parentRunId"] = parent_run_id
        run = self.client.create_run(self.experiment_id(experiment), run_name=run_name, tags=tags)
        return run.info.run_id

    def unique_run_name(self, experiment: str, base: str) -> str:
        """``base``, or ``base·2``, ``base·3`` ... : the first name no run of ``experiment`` has
        (MLflow's own names come from Python's global ``random``, which jt seeds: they collide)."""
        if "'" in base or "\\" in base:
            return base
        exp = self.client.get_experiment_by_name(experiment)
        if exp is None:
            return base
        taken = {r.info.run_name for r in self.client.search_runs(
            [exp.experiment_id], filter_string=f"attributes.run_name LIKE '{base}%'", max_results=50000)}
        if base not in taken:
            return base
        k = 2
        while f"{base}·{k}" in taken:
            k += 1
        return f"{base}·{k}"

    def end_run(self, run_id: str, status: str = "FINISHED", reason: Optional[str] = None) -> None:
        """Close a run with ``FINISHED``, ``FAILED`` or ``KILLED`` (and the reason as a tag)."""
        if reason:
            self.client.set_tag(run_id, "jt.reason", reason[:5000])
        self.client.set_terminated(run_id, status=status)

    def get_run(self, run_id: str) -> Any:
        """The MLflow run; a one-line ``JtError`` if there is none with that id."""
        try:
            return self.client.get_run(run_id)
        except Exception as e:  # noqa: BLE001
            raise JtError(f"no run '{run_id}' in the store {self.root}") from e

    def artifact_dir(self, run_id: str) -> Path:
        """Local folder of a run's artifacts."""
        uri = self.get_run(run_id).info.artifact_uri
        if uri.startswith("file://"):
            uri = uri[len("file://"):]
        return Path(uri)

    def workdir(self, run_id: str, name: str = "") -> Path:
        """Working folder of a run (kept across resumes), created if missing."""
        d = self.root / "work" / run_id / name if name else self.root / "work" / run_id
        d.mkdir(parents=True, exist_ok=True)
        return d

    # ---- logging -------------------------------------------------------------------------
    def log_params(self, run_id: str, params: Mapping[str, Any]) -> None:
        """Log params in batches of 100 (values longer than MLflow's limit are cut)."""
        from mlflow.entities import Param

        items = [Param(str(k), str(v)[:6000]) for k, v in params.items()]
        for i in range(0, len(items), MAX_PARAMS_PER_BATCH):
            self.client.log_batch(run_id, params=items[i : i + MAX_PARAMS_PER_BATCH])

    def set_tags(self, run_id: str, tags: Mapping[str, Any]) -> None:
        """Set several tags in one call."""
        from mlflow.entities import RunTag

        if tags:
            self.client.log_batch(run_id, tags=[RunTag(str(k), str(v)) for k, v in tags.items()])

    def log_artifacts(self, run_id: str, folder: str | os.PathLike, artifact_path: Optional[str] = None) -> None:
        """Copy every file under ``folder`` into the run's artifacts (skipping temp files; an
        ``.h5`` gets its ``.h5.txt`` preview beside it)."""
        folder = Path(folder)
        for p in sorted(folder.rglob("*")):
            if p.is_file() and ".tmp-" not in p.name and p.suffix != ".lock" and not _is_preview(p):
                rel = p.parent.relative_to(folder)
                sub = str(Path(artifact_path) / rel) if artifact_path else (str(rel) if str(rel) != "." else None)
                self.log_artifact(run_id, p, artifact_path=sub)

    def log_artifact(self, run_id: str, path: str | os.PathLike, artifact_path: Optional[str] = None) -> None:
        """Copy one file into the run's artifacts; an HDF5 file (``.h5``) also gets a text preview
        ``<name>.h5.txt`` beside it (groups, datasets, shapes, attributes), which the UI shows."""
        self.client.log_artifact(run_id, str(path), artifact_path=artifact_path)
        if Path(path).suffix == ".h5":
            import tempfile

            from toolkit.store import h5

            with tempfile.TemporaryDirectory(prefix="jt-preview-") as tmp:
                preview = Path(tmp) / f"{Path(path).name}.txt"
                preview.write_text(h5.preview(path))
                self.client.log_artifact(run_id, str(preview), artifact_path=artifact_path)

    def metrics(self, run_id: str) -> "MetricBuffer":
        """A metric buffer for ``run_id`` (flush it, or use it as a context manager)."""
        return MetricBuffer(self, run_id)


def _dispose(uri: str) -> None:
    """Close and forget the engine MLflow keeps for the SQLite database at ``uri`` (its SQLAlchemy
    store caches one per URI, with pooled connections), so the file can be renamed or replaced and
    a later client opens the new one."""
    try:
        from mlflow.store.tracking.sqlalchemy_store import SqlAlchemyStore

        engines = SqlAlchemyStore._engine_map
        lock = SqlAlchemyStore._engine_map_lock
    except (ImportError, AttributeError):  # a private API: without it the pool closes at exit
        return
    with lock:
        engine = engines.pop(uri, None)
    if engine is not None:
        engine.dispose()


def _is_preview(path: Path) -> bool:
    """Whether ``path`` is an HDF5 preview jt writes itself (``x.h5.txt`` beside ``x.h5``)."""
    return path.name.endswith(".h5.txt") and path.with_name(path.name[:-4]).is_file()


def user() -> str:
    """Who runs jt (MLflow's ``mlflow.user``; the UI's "Created by")."""
    import getpass

    try:
        return getpass.getuser()
    except (KeyError, OSError):
        return os.environ.get("USER", "unknown")


class MetricBuffer:
    """Collects metrics and writes them with ``log_batch`` (one ``log_metric`` costs ~8 ms).

    A metric is logged at most once per step: a second value for the same ``(key, step)`` in one
    buffer is dropped (a chart that runs 0.83 → 0.07 at one step helps nobody).

    Args:
        store: the store.
        run_id: run the metrics belong to.
        flush_every: flush automatically once this many metrics are waiting.
    """

    def __init__(self, store: Store, run_id: str, flush_every: int = MAX_METRICS_PER_BATCH) -> None:
        self.store, self.run_id, self.flush_every = store, run_id, flush_every
        self._items: list[Any] = []
        self._seen: set[tuple[str, int]] = set()

    def add(self, key: str, value: float, step: int = 0, timestamp: Optional[float] = None) -> bool:
        """Queue one metric value (NaN/inf are logged as they are; MLflow accepts them).

        Args:
            key: metric name.
            value: its value.
            step: the x of a curve (samples, iterations); 0 for a final value.
            timestamp: when it was measured, Unix seconds (default: now).

        Returns:
            False when ``(key, step)`` was already queued in this buffer (the value is dropped).
        """
        from mlflow.entities import Metric

        if (str(key), int(step)) in self._seen:
            return False
        self._seen.add((str(key), int(step)))
        ts = int(round((timestamp if timestamp is not None else time.time()) * 1000))
        self._items.append(Metric(str(key), float(value), ts, int(step)))
        if len(self._items) >= self.flush_every:
            self.flush()
        return True

    def add_many(self, values: Mapping[str, float], step: int = 0) -> None:
        """Queue several metrics at one step."""
        for k, v in values.items():
            self.add(k, v, step)

    def flush(self) -> None:
        """Write everything queued."""
        while self._items:
            chunk, self._items = self._items[:MAX_METRICS_PER_BATCH], self._items[MAX_METRICS_PER_BATCH:]
            self.store.client.log_batch(self.run_id, metrics=chunk)

    def __enter__(self) -> "MetricBuffer":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.flush()
