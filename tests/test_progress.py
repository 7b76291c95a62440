"""The progress bar (wgcad.cli.progress): moves with the work, never backwards, survives any (done, total) sequence."""

import io
import math
import re

from conftest import TEMPLATES
from hypothesis import given, settings
from hypothesis import strategies as st

from wgcad.cli.progress import Progress, format_seconds

PCT = re.compile(r"\]\s+(\d+) %")


class Clock:
    def __init__(self, step=0.25):
        self.t, self.step = 0.0, step

    def __call__(self):
        self.t += self.step
        return self.t


def percentages(text):
    return [int(m) for m in PCT.findall(text)]


numbers = st.one_of(
    st.integers(-(10**12), 10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.none(),
    st.text(max_size=3),
)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.lists(st.tuples(numbers, numbers, st.one_of(st.none(), st.text(max_size=8))), max_size=40))
def test_any_sequence_is_shown_without_error_and_never_goes_back(calls):
    buf = io.StringIO()
    bar = Progress(True, stream=buf, clock=Clock(), min_interval_s=0.0)
    bar.start("s")
    shown = [bar.fraction]
    for done, total, stage in calls:
        bar(done, total, stage)
        shown.append(bar.fraction)
        assert 0.0 <= bar.fraction <= 1.0 and math.isfinite(bar.fraction)
    assert all(b >= a for a, b in zip(shown, shown[1:]))
    pct = percentages(buf.getvalue())
    assert pct == sorted(pct) and all(0 <= p <= 100 for p in pct)
    bar.close()


def test_fraction_follows_done_over_total_inside_spans():
    bar = Progress(True, stream=io.StringIO(), clock=Clock(), min_interval_s=0.0)
    bar.start()
    bar.span(0.2, 0.6)
    bar(1, 4, "a")
    assert math.isclose(bar.fraction, 0.3)
    bar(3, 4, "a")
    assert math.isclose(bar.fraction, 0.5)
    bar(1, 10, "restarted stage")  # a later stage restarting at 1/10 does not move the bar back
    assert math.isclose(bar.fraction, 0.5)
    bar(99, 4, "past the end")  # done > total is clamped to the span's end
    assert math.isclose(bar.fraction, 0.6)
    bar(5, 0, "zero total")  # ignored, stage still updates
    assert math.isclose(bar.fraction, 0.6) and bar.stage == "zero total"


def test_eta_is_from_the_rate_of_the_work_not_the_start_up():
    clock = Clock(step=0.0)
    bar = Progress(True, stream=io.StringIO(), clock=clock, min_interval_s=0.0)
    bar.start()
    clock.t = 3.0  # three seconds of imports
    bar(1, 10)  # 10 % at t = 3 s: the reference
    clock.t = 5.0
    bar(3, 10)  # 20 % more in 2 s: 70 % left takes 7 s
    assert "ETA 7s" in bar.line()
    bar(10, 10)
    assert "done" in bar.line()


def test_disabled_bar_writes_nothing():
    buf = io.StringIO()
    bar = Progress(False, stream=buf)
    bar.start()
    bar(1, 2, "x")
    bar.close()
    assert buf.getvalue() == ""


def test_broken_stream_does_not_stop_the_run():
    class Broken(io.StringIO):
        def write(self, s):
            raise OSError(28, "No space left on device")

    bar = Progress(True, stream=Broken(), clock=Clock(), min_interval_s=0.0)
    bar.start()
    bar(1, 2, "x")
    bar.close()
    assert not bar.enabled


def test_format_seconds():
    assert [format_seconds(s) for s in (0, 7.4, 65, 3725)] == ["0s", "7s", "1m05s", "1h02m"]


def _record_fractions(monkeypatch):
    # what the bar is asked to show, before the redraw throttle (so the test does not depend on speed)
    seen = []
    real = Progress._draw

    def draw(self, force=False):
        seen.append(round(100 * self.fraction, 3))
        real(self, force)

    monkeypatch.setattr(Progress, "_draw", draw)
    return seen


def test_audit_bar_moves_through_intermediate_fractions(capsys, monkeypatch):
    # the real engine on a real template: the bar starts at 0 %, passes intermediate
    # fractions and ends at 100 % (issue 13: six stages printed together at the end)
    from wgcad.cli import main

    seen = _record_fractions(monkeypatch)
    code = main(["audit", str(TEMPLATES / "d4_discrete.toml"), "--step-deg", "2", "--progress", "--quiet"])
    err = capsys.readouterr().err
    assert code in (0, 1)
    assert seen[0] == 0 and seen[-1] == 100 and seen == sorted(seen)
    assert len({p for p in seen if 0 < p < 100}) >= 3, seen
    pct = percentages(err)  # what was drawn: a subset, in order, starting at 0 and ending at 100
    assert pct[0] == 0 and pct[-1] == 100 and pct == sorted(pct)
    assert err.endswith("\n") and "Traceback" not in err


def test_generate_bar_moves_per_file(capsys, tmp_path, monkeypatch):
    from wgcad.cli import main

    seen = _record_fractions(monkeypatch)
    code = main(["generate", str(TEMPLATES / "d4_discrete.toml"), "--out", str(tmp_path), "--progress", "--quiet"])
    err = capsys.readouterr().err
    assert code == 0
    assert seen[0] == 0 and seen[-1] == 100 and seen == sorted(seen)
    assert len({p for p in seen if 0 < p < 100}) >= 3, seen
    pct = percentages(err)
    assert pct[0] == 0 and pct[-1] == 100 and pct == sorted(pct)
    # the last state says "done" once (issue 23: it read "done       done")
    last = err.replace("\r", "\n").strip().splitlines()[-1]
    assert last.count("done") == 1, last


def test_parts_bar_moves_per_part(capsys, tmp_path, monkeypatch):
    # issue 23: parts was silent for its whole run (30 s then, 6 s now on D1)
    from test_parts import small_design

    from wgcad.cli import main

    seen = _record_fractions(monkeypatch)
    design = small_design(tmp_path)
    code = main(["parts", str(design), "--out", str(tmp_path / "out"), "--format", "stl,step", "--progress", "--quiet"])
    err = capsys.readouterr().err
    assert code == 0
    assert seen[0] == 0 and seen[-1] == 100 and seen == sorted(seen)
    assert len({p for p in seen if 0 < p < 100}) >= 5, seen
    last = err.replace("\r", "\n").strip().splitlines()[-1]
    assert last.count("done") == 1, last


def test_sector_and_ke_bars_move(capsys, tmp_path, monkeypatch):
    # issue 23: ke and sector had no progress (4 s and 2.5 s of silence)
    from wgcad.cli import main

    for cmd in (
        ["sector", str(TEMPLATES / "d4_sectored.toml"), "--out", str(tmp_path / "s"), "--no-stl", "--json"],
        ["ke", str(TEMPLATES / "d2_imperfect.toml"), "--per-mesh", "4"],
    ):
        seen = _record_fractions(monkeypatch)
        main([*cmd, "--progress"])
        err = capsys.readouterr().err
        assert seen[0] == 0 and seen[-1] == 100 and seen == sorted(seen), (cmd[0], seen)
        assert len({p for p in seen if 0 < p < 100}) >= 3, (cmd[0], seen)
        assert err.replace("\r", "\n").strip().splitlines()[-1].count("done") == 1
