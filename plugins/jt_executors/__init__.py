"""Built-in executors: ``local`` (process pool) and ``ray`` (a Ray cluster)."""
