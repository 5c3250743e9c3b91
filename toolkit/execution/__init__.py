"""Run orchestration: compose → searcher ask/tell loop → evaluations (nested runs) → store."""
