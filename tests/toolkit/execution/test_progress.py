"""A run's progress: a live bar with an ETA on a terminal, rate-limited plain lines elsewhere, and
worker processes reporting through the executor's queue (issue 31)."""

from __future__ import annotations

import functools
import io
import subprocess
import time

import pytest

from toolkit.execution import progress as P


def test_lines_off_a_terminal_are_rate_limited_and_plain(monkeypatch):
    monkeypatch.setattr(P, "QUIET_S", 0.0)
    out = io.StringIO()
    bar = P.RunProgress(4, 1, "task=getup", out=out, how="lines")
    for k in range(50):  # 50 reports inside one LINE_EVERY_S: one line
        bar.update(1, k / 100, f"success 0.{k:02d}")
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 and "ETA" in lines[0] and "eval 1" in lines[0] and "(1/4 done)" in lines[0]
    monkeypatch.setattr(P, "LINE_EVERY_S", 0.0)
    bar.update(1, 0.5, "success 0.50")
    bar.finished(1, "jt: [2/4] eval 1 in 3.0s success=0.5")
    text = out.getvalue()
    assert "jt: [2/4] eval 1" in text and "\x1b" not in text and "\r" not in text
    assert bar.fraction() == pytest.approx(0.5)


def test_the_eta_follows_the_pace_so_far(monkeypatch):
    bar = P.RunProgress(10, 0, out=io.StringIO(), how="lines")
    assert bar.eta() is None
    bar.t0 -= 30.0  # 30 s in, half an evaluation done: 9.5 evaluations left at 60 s each
    bar.update(0, 0.5)
    assert bar.eta() == pytest.approx(570.0, rel=0.01)


def test_on_a_terminal_one_bar_for_the_run_and_one_per_running_evaluation(monkeypatch):
    from rich.console import Console

    monkeypatch.setattr(P, "QUIET_S", 0.0)
    buf = io.StringIO()
    console = Console(file=buf, force_terminal=True, width=140, color_system=None)
    bar = P.RunProgress(3, 0, "task=highjump", console=console)
    bar.update(0, 0.25, "success 0.10")
    bar.update(1, 0.50, "success 0.20")
    assert len(bar.eval_tasks) == 2
    bar.bar.refresh()
    bar.finished(0, "jt: [1/3] eval 0 in 1.0s")
    assert len(bar.eval_tasks) == 1
    bar.close()
    text = buf.getvalue()
    assert "task=highjump" in text and "ETA" in text and "eval 1" in text and "jt: [1/3] eval 0" in text
    assert "\x1b" in text or "\r" in text  # drawn live, not as lines


def test_mode_is_lines_in_ci_and_when_forced(monkeypatch):
    monkeypatch.setenv("CI", "true")
    assert P.mode() == "lines"
    monkeypatch.setenv("JT_PROGRESS", "bar")
    assert P.mode() == "bar"


def test_worker_processes_report_through_the_executors_queue():
    from omegaconf import OmegaConf

    from toolkit import plugins

    ex = plugins.load("executor", "local")(OmegaConf.create({"name": "local", "workers": 2,
                                                             "start_method": "spawn"}))
    try:
        q = ex.progress_queue()
        bar = P.RunProgress(2, 0, out=io.StringIO(), how="lines")
        pump = bar.pump(q)
        report = functools.partial(P.Channel(q), fraction=0.5, message="half")
        assert sorted(i for i, _ in ex.imap(report, [0, 1])) == [0, 1]
        deadline = time.monotonic() + 10
        while len(bar.running) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        pump.stop()
        assert {i: e[:2] for i, e in bar.running.items()} == {0: [0.5, "half"], 1: [0.5, "half"]}
    finally:
        ex.close()


def test_a_piped_run_has_no_control_characters(tmp_path):
    out = subprocess.run(["jt", "run", "task=spd_tracking", "experiment=smoke", f"store={tmp_path / 's'}"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "\x1b" not in out.stdout + out.stderr and "\r" not in out.stdout + out.stderr
    assert "jt: [1/1] eval 0" in out.stderr


def test_a_figure_that_does_not_exist_yet_is_a_dash():
    assert P.figure(float("nan")) == "—" and P.figure(None) == "—" and P.figure(float("inf"), missing="-") == "-"
    assert P.figure(0.12345, ".2f") == "0.12"
