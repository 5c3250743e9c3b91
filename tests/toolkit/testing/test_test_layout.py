"""The test tree never shadows the plugin packages.

pytest puts the folder of every test module on ``sys.path``. A test module directly in
``tests/plugins/`` would put that folder there, and its ``jt_tasks/``, ``jt_bullet/`` ...
subfolders (no ``__init__.py``: namespace packages) would then shadow the real plugin packages in
spawned worker processes (``No module named 'jt_tasks.jumping.task'`` in a rollout pool)."""

from pathlib import Path

TESTS = Path(__file__).resolve().parents[2]


def test_no_test_module_directly_under_tests_plugins():
    assert not sorted(p.name for p in (TESTS / "plugins").glob("*.py")), \
        "move these into a subfolder (e.g. tests/toolkit/testing/)"
