"""Result.save from several threads: saves of different results go on at once (a
process-wide lock made each wait for the other, for PLplot's global state, which only
the library's child processes touch: docs/reliability.md), saves of one result take
turns (the run records its writing time: a handle is used by one thread at a time), and
either way the files are byte for byte those of serial saves (summary.json but for its
timings)."""
import filecmp
import json
import os
import threading

import thzmap


def same_files(got, want):
    names = sorted(os.listdir(want))
    assert sorted(os.listdir(got)) == names, (got, want)
    for name in names:
        a, b = os.path.join(got, name), os.path.join(want, name)
        if name == "summary.json":
            with open(a) as fa, open(b) as fb:
                ja, jb = json.load(fa), json.load(fb)
            ja.pop("timings_s"), jb.pop("timings_s")
            assert ja == jb, f"{a} differs from {b} but for timings_s"
        else:
            assert filecmp.cmp(a, b, shallow=False), f"{a} differs from {b}"


def run_threads(works):
    errors = []

    def guard(fn):
        try:
            fn()
        except BaseException as e:  # reported in the main thread
            errors.append(e)
    threads = [threading.Thread(target=guard, args=(w,)) for w in works]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert not any(t.is_alive() for t in threads), "a save still going on after 120 s"
    assert not errors, errors


def test_saves_of_two_results_go_on_at_once(tiny_dir):
    """Thread A's save waits, in its first progress report, for thread B's save of
    another result to end: B's must not wait for A's."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    results = [thzmap.simulate(scene, seed=11, threads=1),
               thzmap.simulate(scene, seed=12, integrator="path", threads=1)]
    for k, r in enumerate(results):
        r.save(tiny_dir / f"serial-{k}")
    inside_a, b_done = threading.Event(), threading.Event()
    waited = []

    def report(p):
        if not inside_a.is_set():
            inside_a.set()
            waited.append(b_done.wait(20))

    def save_a():
        results[0].save(tiny_dir / "thread-0", progress=report)

    def save_b():
        assert inside_a.wait(60), "thread A's save made no progress report"
        results[1].save(tiny_dir / "thread-1")
        b_done.set()
    run_threads([save_a, save_b])
    assert waited == [True], "B's save waited for A's, which was going on"
    for k in range(2):
        same_files(tiny_dir / f"thread-{k}", tiny_dir / f"serial-{k}")


def test_saves_of_one_result_take_turns(tiny_dir):
    """One result saved by four threads at once into four directories: each as a
    serial save's."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    result = thzmap.simulate(scene, seed=11, threads=1)
    result.save(tiny_dir / "serial")
    run_threads([lambda k=k: result.save(tiny_dir / f"thread-{k}") for k in range(4)])
    for k in range(4):
        same_files(tiny_dir / f"thread-{k}", tiny_dir / "serial")
    assert "output" in result.summary["timings_s"], result.summary["timings_s"]
