"""A store served by an MLflow tracking server: ``store=http://host:port`` (or ``JT_STORE``).

The server holds the tracking data and, started with ``--serve-artifacts``, the artifacts; jt
talks to it over HTTP only, so the driver and the server need not share a filesystem (and Ray
workers never talk to it at all: they return results and files to the driver). Start one with::

    mlflow server --backend-store-uri sqlite:///PATH/mlflow.db --artifacts-destination PATH/artifacts \\
        --serve-artifacts --host 0.0.0.0 --port 5000 --workers 1

What stays on the driver is a cache folder, ``$JT_WORK_DIR/<host>_<port>/`` (default
``~/.cache/jt/<host>_<port>/``; ``XDG_CACHE_HOME`` moves ``~/.cache``):

``work/<run_id>/``
    the working folders a run resumes from (config, search history, evaluation checkpoints),
    as ``<store>/work/`` of a local store; ``jt run resume=`` must run where they are.
``artifacts/<run_id>/``
    a run's artifacts downloaded from the server, for ``jt show`` and for reading them back
    (``Store.artifact_dir``); ``artifacts/<run_id>.synced`` holds the run's status and end time
    at the download, which is repeated when they change (and always for a RUNNING run).
"""

from __future__ import annotations

import os
import re
import shutil
import urllib.error
import urllib.request
from pathlib import Path
from typing import Optional
from urllib.parse import urlparse

from toolkit.errors import JtError
from toolkit.store.tracking import Store, is_server_uri, quiet_mlflow_logs

HEALTH_TIMEOUT_S = 5.0
_REMOTE_SCHEMES = ("mlflow-artifacts", "http", "https", "s3", "gs", "wasbs", "abfss", "hdfs", "dbfs", "sftp", "ftp")
START = ("mlflow server --backend-store-uri sqlite:///PATH/mlflow.db --artifacts-destination PATH/artifacts "
         "--serve-artifacts --host 0.0.0.0 --port 5000 --workers 1")


def cache_root(uri: str) -> Path:
    """The driver-side folder of server ``uri``: ``$JT_WORK_DIR`` (or ``~/.cache/jt``) / ``host_port``."""
    parsed = urlparse(uri)
    name = re.sub(r"[^A-Za-z0-9._-]+", "_", f"{parsed.netloc}{parsed.path}".replace(":", "_")).strip("_")
    base = os.environ.get("JT_WORK_DIR")
    if not base:
        base = str(Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "jt")
    return Path(base).expanduser().resolve() / (name or "server")


def check_health(uri: str, timeout_s: float = HEALTH_TIMEOUT_S) -> None:
    """A one-line ``JtError`` unless an MLflow server answers ``GET <uri>/health`` (the client
    itself would retry a dead address for minutes)."""
    try:
        with urllib.request.urlopen(f"{uri}/health", timeout=timeout_s) as resp:
            if resp.status == 200:
                return
            why = f"HTTP {resp.status}"
    except urllib.error.HTTPError as e:
        why = f"HTTP {e.code}"
    except (urllib.error.URLError, OSError) as e:
        why = str(getattr(e, "reason", e))
    raise JtError(f"store={uri}: no MLflow server answers there ({why}); start one with: {START}")


class ServerStore(Store):
    """``Store`` backed by an MLflow tracking server (``Store(uri)`` returns one for a URI).

    Args:
        root: the server URI, ``http://host:port`` or ``https://...``.

    Attributes:
        root: the URI (what ``store=`` takes, so ``store={store.root}`` hints work).
        uri: the same URI (MLflow's tracking URI).
        cache: the driver-side folder (see the module docstring).
    """

    is_server = True

    def __init__(self, root: str | os.PathLike, must_exist: bool = False) -> None:  # noqa: D107 - documented on the class
        uri = str(root).rstrip("/")
        if not is_server_uri(uri):
            raise JtError(f"store={root}: not an http(s):// MLflow server URI")
        self.root = self.uri = uri
        self.cache = cache_root(uri)
        check_health(uri)
        from mlflow.tracking import MlflowClient

        quiet_mlflow_logs()
        # MLflow prints two "View run ... at" lines (and fetches the run again) per ended run
        os.environ.setdefault("MLFLOW_SUPPRESS_PRINTING_URL_TO_STDOUT", "true")
        self.client = MlflowClient(tracking_uri=uri)
        try:
            self.client.search_experiments(max_results=1)
        except Exception as e:  # noqa: BLE001 - MLflow raises its own types; say it in one line
            first = (str(e).strip().splitlines() or [type(e).__name__])[0][:300]
            raise JtError(f"store={uri}: the server answers but refuses jt ({first}); a 403 means the "
                          f"server's --allowed-hosts lacks '{urlparse(uri).netloc}'") from None

    # ---- experiments -----------------------------------------------------------------------
    def experiment_id(self, name: str) -> str:
        """Id of experiment ``name``, created with the server's own artifact location."""
        exp = self.client.get_experiment_by_name(name)
        if exp is None:
            try:
                self.client.create_experiment(name)
            except Exception:  # noqa: BLE001 - another process created it first
                pass
            exp = self.client.get_experiment_by_name(name)
            if exp is None:
                raise JtError(f"store={self.uri}: could not create experiment '{name}'")
        scheme = urlparse(exp.artifact_location or "").scheme
        if scheme not in _REMOTE_SCHEMES:
            raise JtError(f"store={self.uri}: experiment '{name}' keeps artifacts at {exp.artifact_location}, "
                          "a path on the server's machine that this one cannot write; start the server with "
                          "--serve-artifacts --artifacts-destination DIR (and a fresh backend store)")
        return exp.experiment_id

    # ---- folders ---------------------------------------------------------------------------
    def workdir(self, run_id: str, name: str = "") -> Path:
        """Working folder of a run in the driver's cache (kept across resumes), created if missing."""
        d = self.cache / "work" / run_id / name if name else self.cache / "work" / run_id
        d.mkdir(parents=True, exist_ok=True)
        return d

    def artifact_dir(self, run_id: str) -> Path:
        """A local copy of the run's artifacts, downloaded from the server when the run changed."""
        run = self.get_run(run_id)
        dst = self.cache / "artifacts" / run_id
        state = f"{run.info.status} {run.info.end_time}"
        mark = dst.with_name(f"{run_id}.synced")
        if run.info.status != "RUNNING" and mark.is_file() and mark.read_text() == state:
            return dst
        tmp = dst.with_name(f"{run_id}.tmp-{os.getpid()}")
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        try:
            if self.client.list_artifacts(run_id):
                self.client.download_artifacts(run_id, "", str(tmp))
            shutil.rmtree(dst, ignore_errors=True)
            tmp.rename(dst)
            mark.write_text(state)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        return dst

    def fetch(self, run_id: str, name: str, folder: str | os.PathLike) -> Optional[Path]:
        """Download the artifact ``name`` of a run into ``folder``; its path, or None if absent."""
        parent = str(Path(name).parent) if "/" in name else None
        if not any(f.path == name for f in self.client.list_artifacts(run_id, parent)):
            return None
        return Path(self.client.download_artifacts(run_id, name, str(folder)))
