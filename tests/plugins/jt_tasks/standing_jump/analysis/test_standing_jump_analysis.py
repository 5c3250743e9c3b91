"""``jt study standing_jump hypervolume`` and ``bench`` (jt_tasks.standing_jump.analysis): their inputs
are checked before any simulation, each mistake one line with exit status 2; the benchmark's JSON."""

from __future__ import annotations

import json

import pytest


@pytest.mark.parametrize("tool, argv, match", [
    ("study", ["--budget", "0"], "--budget=0: at least 1 simulation"),
    ("study", ["--workers", "0"], "--workers=0: at least 1 process"),
    ("study", ["--out", "{tmp}/file/study"], "--out={tmp}/file/study: cannot write there"),
    ("study", ["--searchers", "cmaes"], "jt study standing_jump hypervolume: argument --searchers: invalid choice"),
    ("bench", ["--n", "0"], "--n=0: at least 1 evaluation"),
    ("bench", ["--sim-hz", "nan"], "--sim-hz=nan: a finite rate > 0"),
    ("bench", ["--spd", "servo"], "--spd=servo: not an SPD backend the standing jump can use; choose one of: df, maba"),
    ("bench", ["--json", "{tmp}/file/b.json"], "--json={tmp}/file/b.json: cannot write there"),
])
def test_bad_input_is_one_line_before_any_simulation(tmp_path, capsys, tool, argv, match):
    import importlib

    main = importlib.import_module(f"jt_tasks.standing_jump.analysis.{tool}").main
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as e:
        main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    out, err = capsys.readouterr()
    assert e.value.code == 2 and out == "" and err.startswith("jt: ") and len(err.strip().splitlines()) == 1
    assert match.replace("{tmp}", str(tmp_path)) in err


def test_bench_writes_its_json(tmp_path, capsys):
    from jt_tasks.standing_jump.analysis.bench import main

    main(["--n", "1", "--json", str(tmp_path / "out" / "bench.json")])
    res = json.loads((tmp_path / "out" / "bench.json").read_text())
    assert len(res["wall_s"]) == 1 and res["spd"] == "maba" and "1 evaluations at 600 Hz" in capsys.readouterr().out
