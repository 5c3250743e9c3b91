"""jt show: a run's description and summary table; one artifact (an HDF5 file as its preview)."""

import pytest

from tests.conftest import run_jt
from toolkit.config import compose
from toolkit.errors import JtError
from toolkit.execution.runner import run
from toolkit.execution.show import show


def test_show_prints_description_summary_table_and_one_artifact(example_plugin, store_dir):
    res = run(compose(["task=quadratic", "search=random", "search.budget=2", "search.batch=2",
                       "executor.workers=1", f"store={store_dir}", "seed=1"]))
    text = show(res.run_id, str(store_dir))
    assert "description:\n  **quadratic · random · seed 1**" in text
    table = text.split("summary table:\n", 1)[1].splitlines()
    assert table[0].split() == ["eval", "x0", "x1", "value"] and set(table[1]) <= {" ", "-"}
    assert len(table[2].split()) == 4 and table[2].split()[0] == "0"
    assert "points.png" in text and "search.h5.txt" in text
    h5_text = show(res.run_id, str(store_dir), artifact="search.h5")
    assert h5_text.startswith("search.h5: HDF5, ") and "\nhistory/\n" in h5_text
    assert "\nseed: 1\n" in show(res.run_id, str(store_dir), artifact="config.yaml")
    assert "PNG image, 320 × 320 px" in show(res.run_id, str(store_dir), artifact="points.png")
    with pytest.raises(JtError, match="has no artifact 'nope.h5'; it has: config.yaml, points.png"):
        show(res.run_id, str(store_dir), artifact="nope.h5")
    with pytest.raises(JtError, match="has no artifact"):
        show(res.run_id, str(store_dir), artifact="../../mlflow.db")


def test_show_artifact_from_the_command_line(example_plugin, store_dir):
    res = run(compose(["task=quadratic", "executor.workers=1", f"store={store_dir}"]))
    p = run_jt("show", res.run_id, f"store={store_dir}", "--artifact", "evaluation.h5", extra_path=example_plugin)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("evaluation.h5: HDF5") and "noise  8 float64" in p.stdout
    bad = run_jt("show", res.run_id, f"store={store_dir}", "--artifact", "x.h5", extra_path=example_plugin)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    assert bad.stderr.startswith(f"jt: run {res.run_id} has no artifact 'x.h5'")
