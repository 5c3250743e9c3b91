"""Built-in searchers: single, random, bds, rmoo, bsoo."""
