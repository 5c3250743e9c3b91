"""One torch thread for the learner in these tests: small nets, and 2 shared cores."""

import pytest


@pytest.fixture(autouse=True)
def _one_torch_thread(one_torch_thread):
    yield
