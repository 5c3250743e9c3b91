"""executor=ray on a throwaway single-machine Ray instance (skipped when Ray is not installed).

Ray is an optional extra (``pip install -e '.[ray]'``) and slow to start, so this is a slow test.
"""

import pytest

from toolkit.testing.executor import ExecutorContract

pytestmark = pytest.mark.slow


class TestRay(ExecutorContract):
    entry = "ray"

    @pytest.fixture(scope="class")
    def executor(self):
        ray = pytest.importorskip("ray")
        from jt_executors.ray import RayExecutor

        ray.init(num_cpus=2, include_dashboard=False, ignore_reinit_error=True)
        ex = RayExecutor(RayExecutor.Config(workers=2))
        yield ex
        ex.close()
        ray.shutdown()
