"""The store: MLflow tracking in SQLite (``<root>/mlflow.db``) and artifacts as files (``<root>/``).

``h5`` writes and reads HDF5 artifacts atomically; ``tracking`` opens the store, buffers metrics
and logs them with ``log_batch``; ``resolve`` finds the artifact a run id, folder or file names
(``task.init``, ``task.takeoff_from``, ``action.prior``).
"""
