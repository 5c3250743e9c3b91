"""Deterministic seeds: every evaluation, worker and actor gets a seed derived from the run seed."""

from __future__ import annotations

import random


def derive(seed: int, *keys: int) -> int:
    """A 31-bit seed derived from ``seed`` and integer ``keys`` (e.g. evaluation index).

    Uses numpy's ``SeedSequence`` so derived streams are independent and the mapping is stable
    across machines and Python versions.
    """
    import numpy as np

    ss = np.random.SeedSequence([int(seed) & 0xFFFFFFFF, *[int(k) & 0xFFFFFFFF for k in keys]])
    return int(ss.generate_state(1, dtype=np.uint32)[0] >> 1)


def seed_everything(seed: int) -> None:
    """Seed Python's, numpy's and (if already imported) torch's global generators."""
    import sys

    import numpy as np

    random.seed(seed)
    np.random.seed(seed % (2**32))
    if "torch" in sys.modules:
        sys.modules["torch"].manual_seed(seed)
