"""Progress output in a log file: plain lines at each step of the total, no carriage returns."""

import io

from flexgear.progress import Progress, say


def test_plain_lines_when_not_a_terminal():
    log = io.StringIO()
    with Progress(0.1, "run model1", "s", stream=log, fmt="{:.4g}") as bar:
        for k in range(1, 101):
            bar.update_to(k * 1e-3, postfix="ok")
    say("done", stream=log)
    lines = log.getvalue().splitlines()
    assert "\r" not in log.getvalue()
    assert [line.split(":", 1)[1].split("(")[1].split(")")[0] for line in lines[:4]] == ["25 %", "50 %", "75 %",
                                                                                         "100 %"]
    assert lines[3].startswith("run model1: 0.1/0.1 s") and lines[3].endswith("ok") and lines[4] == "done"
