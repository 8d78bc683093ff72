"""Cancelling: a progress callback that returns True, raises, or a Ctrl-C (SIGINT)
stops the run; the call raises, nothing is returned or written, and the interpreter
goes on (the next run works)."""
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
import thzmap
from conftest import REPO


def test_progress_callback_sees_the_stages(tiny_dir):
    seen = []
    thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), progress=seen.append)
    stages = {p.stage for p in seen}
    assert stages == {"photons", "render"}
    last = [p for p in seen if p.stage == "photons" and p.channel == 1][-1]
    assert (last.done, last.total, last.n_channels) == (3000, 3000, 2)


def test_callback_returning_true_cancels(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    calls = []
    with pytest.raises(thzmap.CancelledError):
        thzmap.simulate(scene, progress=lambda p: calls.append(p) or True)
    assert len(calls) == 1  # the run stopped at the first report
    assert thzmap.simulate(scene).sensors == ["cam"]  # and the next one works


def test_callback_exception_cancels_and_propagates(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")

    def boom(p):
        raise ZeroDivisionError("from the callback")
    with pytest.raises(ZeroDivisionError, match="from the callback"):
        thzmap.simulate(scene, progress=boom)

    def interrupt(p):
        raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        thzmap.simulate(scene, progress=interrupt)
    assert thzmap.simulate(scene).sensors == ["cam"]


def test_sigint_during_a_run_raises_keyboard_interrupt(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    reports = []

    def ctrl_c_once(p):
        reports.append(p)
        if len(reports) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # as a Ctrl-C would, mid-run
    with pytest.raises(KeyboardInterrupt):
        thzmap.simulate(scene, progress=ctrl_c_once)
    assert len(reports) <= 2
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert thzmap.simulate(scene).sensors == ["cam"]


def test_cancelled_save_leaves_nothing(tiny_dir):
    result = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"))
    out = tiny_dir / "out"
    with pytest.raises(thzmap.CancelledError):
        result.save(out, progress=lambda p: True)
    assert not out.exists()
    (tiny_dir / "old").mkdir()
    (tiny_dir / "old" / "keep.txt").write_text("x")
    with pytest.raises(KeyboardInterrupt):
        result.save(tiny_dir / "old", progress=lambda p: (_ for _ in ()).throw(KeyboardInterrupt))
    assert os.listdir(tiny_dir / "old") == ["keep.txt"]
    result.save(out)
    assert (out / "cam.radiance.img").exists()


def test_real_ctrl_c_from_outside(tiny_dir):
    """A separate interpreter runs a long simulate with no callback of its own; SIGINT
    sent from outside stops it within a second, and the interpreter runs on."""
    script = textwrap.dedent(f"""
        import sys, time, thzmap
        scene = thzmap.load_scene({str(tiny_dir / "scene.json")!r})
        print("start", flush=True)
        t = time.monotonic()
        try:
            thzmap.simulate(scene, photons=50_000_000, threads=1)
            print("finished", flush=True)
        except KeyboardInterrupt:
            print("interrupted %.2f" % (time.monotonic() - t), flush=True)
        print("next", thzmap.simulate(scene).sensors, flush=True)
    """)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.join(REPO, "python"), os.environ.get("PYTHONPATH", "")]))
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env)
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.0)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    stopped_after = time.monotonic() - sent
    lines = out.split("\n")
    assert lines[0].startswith("interrupted"), out + err
    assert lines[1] == "next ['cam']", out + err
    assert stopped_after < 10, stopped_after
    assert "Exception ignored" not in err and "Traceback" not in err, err


def test_progress_bar_never_runs_backwards(monkeypatch):
    """progress=True: a run that adds passes reports each pass's rows from 0 again; the
    bar starts anew there instead of counting down."""
    import types
    from thzmap.progress import Progress, _Bar
    bars = []

    class FakeBar:
        def __init__(self, total, **kw):
            self.total, self.n, self.updates = total, 0, []
            bars.append(self)

        def update(self, k):
            self.updates.append(k)
            self.n += k

        def close(self):
            pass
    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    bar = _Bar()
    for done in (16, 64, 8, 64):  # pass 1 of 64 rows, then pass 2
        bar(Progress("render", 0, 1, done, 64))
    bar(Progress("render", 1, 1, 64, 64))
    bar.close()
    assert [b.updates for b in bars] == [[16, 48], [8, 56], [64]]


def test_progress_true_prints_each_stage_to_its_end_and_false_prints_nothing(
        tiny_dir, monkeypatch, capfd):
    """Without tqdm, progress=True prints "thzmap: channel C/N STAGE: DONE/TOTAL UNIT"
    lines on stderr, channels counted from 1, each stage's last line at its end (done =
    total, however soon it comes); progress=False and None print nothing, as for the
    CLI's --quiet."""
    import re
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm fails
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    for quiet in (None, False):
        thzmap.simulate(scene, seed=1, progress=quiet)
        assert capfd.readouterr().err == ""
    thzmap.simulate(scene, seed=1, progress=True)
    lines = capfd.readouterr().err.splitlines()
    last = {}
    units = {"photons": "photons", "render": "rows"}
    for line in lines:
        m = re.fullmatch(r"thzmap: channel (\d+)/2 (\w+): (\d+)/(\d+) (\w+)", line)
        assert m, line
        c, stage, done, total, unit = m.groups()
        assert c in ("1", "2") and unit == units[stage], line
        last[(c, stage)] = (done, total)
    assert set(last) == {(c, s) for c in ("1", "2") for s in ("photons", "render")}
    assert all(done == total for done, total in last.values()), last


def test_progress_bars_are_closed_when_the_run_ends(tiny_dir, monkeypatch):
    """With tqdm, progress=True leaves no bar open once the call returns."""
    import types
    bars = []

    class FakeBar:
        def __init__(self, total, **kw):
            self.total, self.n, self.closed = total, 0, False
            bars.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True
    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), seed=1, progress=True)
    assert bars and all(b.closed for b in bars)
