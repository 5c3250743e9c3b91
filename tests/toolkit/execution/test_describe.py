"""Run descriptions: markdown tables, headline metrics first, never longer than MLflow keeps."""

from omegaconf import OmegaConf

from toolkit.execution import describe


def test_a_long_summary_table_is_cut_by_rows_and_the_text_fits_mlflow():
    cfg = OmegaConf.create({"task": {"name": "highjump"}, "search": {"name": "bds", "budget": 100}, "seed": 0})
    rows = [[i, f"strategy {i} " + "x" * 150, 0.5] for i in range(100)]
    text = describe.outer(cfg, "jt run task=highjump search=bds", {"n_evaluations": 100.0, "best_mean_return": 0.8},
                          ("mean_return",), ["gallery.png"], True, describe.table(["eval", "what", "h"], rows))
    assert len(text) <= describe.LIMIT
    assert text.splitlines()[2:4] == ["| metric | value |", "|---|---|"]
    assert text.splitlines()[4] == "| best_mean_return | 0.8 |"  # the key metric's best first
    assert "| 39 | strategy 39 " in text and "| 40 | strategy 40 " not in text
    assert "… 60 more rows (all of them: `jt show RUN_ID`)" in text


def test_fit_cuts_at_a_line_and_says_so():
    text = describe.fit("| row | 1 |\n" * 2000)
    assert len(text) <= describe.LIMIT and text.endswith("prints everything)\n")
    assert all(ln == "| row | 1 |" for ln in text.split("\n\n…")[0].splitlines())
    assert describe.fit("short\n") == "short\n"


def test_table_escapes_pipes_and_formats_numbers():
    assert describe.table(["k", "v"], [["a|b", 0.123456], ["n", float("nan")]]).splitlines()[2:] == \
        ["| a\\|b | 0.1235 |", "| n | nan |"]
