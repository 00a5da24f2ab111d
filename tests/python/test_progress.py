"""Long calls from Python: the progress callback (called with the GIL held, from whichever
thread the library reports on), cancellation by returning False, an exception raised in
the callback reaching the caller unchanged, and Ctrl-C (SIGINT) stopping a call that is
busy in C++ with KeyboardInterrupt, after which the interpreter's own SIGINT handling is
back as it was."""
import os
import signal
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import omnical


@pytest.fixture
def sensor(data):
    return omnical.Sensor.load(data / "sensors" / "ohte-sph-misaligned.yaml")


def test_progress_counts_every_row_then_every_distance(sensor):
    updates = []
    omnical.remap(sensor, "panorama", size=(128, 32), n=7, threads=2, progress=lambda *u: updates.append(u))
    rows = [u for u in updates if u[0] == "remap table"]
    # One report per row after the first (0), counts never going back although two
    # threads report, the last one the total.
    done = [d for _, d, _ in rows]
    assert rows[0] == ("remap table", 0, 32) and len(rows) == 33
    assert done == sorted(done) and done[-1] == 32
    assert any(u[0] == "remap error" for u in updates)


def test_returning_false_cancels_with_cancelled(sensor):
    calls = []

    def stop_at_the_fifth(stage, done, total):
        calls.append(done)
        return len(calls) < 5
    with pytest.raises(omnical.Cancelled, match="cancelled during remap table"):
        omnical.remap(sensor, "panorama", size=(256, 64), n=7, threads=1, progress=stop_at_the_fifth)
    assert len(calls) == 5  # not called again once it said stop
    # None and True mean go on.
    omnical.remap(sensor, "panorama", size=(64, 16), n=7, progress=lambda *u: None)


def test_an_exception_in_the_callback_reaches_the_caller(sensor):
    class Mine(Exception):
        pass

    def fail(stage, done, total):
        if done == 3:
            raise Mine("from the callback")
    with pytest.raises(Mine, match="from the callback"):
        omnical.remap(sensor, "panorama", size=(256, 64), n=7, threads=2, progress=fail)


def test_a_call_from_another_thread_reports_and_finishes(sensor):
    result, updates = {}, []

    def work():
        result["maps"] = omnical.remap_tables(sensor, "panorama", n=7, size=(64, 16), progress=lambda *u: updates.append(u))
    worker = threading.Thread(target=work)
    worker.start()
    worker.join(timeout=60)
    assert result["maps"][0].shape == (16, 64) and updates


def test_calls_from_several_threads_at_once_give_the_sequential_answers(sensor, data):
    other = omnical.Sensor.load(data / "sensors" / "ohte-edi.yaml")
    jobs = [(sensor, "panorama", 7.0), (other, "perspective", 5.0), (sensor, "lonlat", 3.0), (other, "panorama", 9.0)]
    sequential = [omnical.remap_tables(s, view, n=n, size=(96, 48)) for s, view, n in jobs]
    results = [None] * len(jobs)

    def run(i):
        s, view, n = jobs[i]
        results[i] = omnical.remap_tables(s, view, n=n, size=(96, 48), threads=1)
    threads = [threading.Thread(target=run, args=(i,)) for i in range(len(jobs))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=120)
    for (x, y), (sx, sy) in zip(results, sequential):
        np.testing.assert_array_equal(x, sx)
        np.testing.assert_array_equal(y, sy)


CHILD = textwrap.dedent("""
    import signal, sys, time
    import omnical
    sensor = omnical.Sensor.load(sys.argv[1])
    progress = None if sys.argv[2] == "none" else (lambda stage, done, total: True)
    print("started", flush=True)
    start = time.monotonic()
    try:
        omnical.remap(sensor, "panorama", size=(8192, 4096), n=7, per_pixel=True, threads=1, progress=progress)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print(f"interrupted {time.monotonic() - start:.2f}", flush=True)
    # The interpreter's SIGINT handling is back: the next Ctrl-C interrupts plain Python.
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    try:
        print("ready", flush=True)
        time.sleep(30)
    except KeyboardInterrupt:
        print("python interrupted", flush=True)
""")


@pytest.mark.parametrize("progress", ["none", "callback"])
def test_ctrl_c_stops_a_long_call_with_keyboard_interrupt(data, progress, tmp_path):
    """The table (8192 x 4096 per pixel, one thread) takes ~10 s; SIGINT 0.5 s in must end
    it within a second or two (the rows are reported every few ms)."""
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    child = subprocess.Popen([sys.executable, str(script), str(data / "sensors" / "ohte-sph-misaligned.yaml"), progress],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=os.environ)
    try:
        assert child.stdout.readline().strip() == "started"
        threading.Event().wait(0.5)
        child.send_signal(signal.SIGINT)
        line = child.stdout.readline().split()
        assert line[0] == "interrupted", (line, child.stderr.read())
        assert float(line[1]) < 3.0
        assert child.stdout.readline().strip() == "ready"
        child.send_signal(signal.SIGINT)
        assert child.stdout.readline().strip() == "python interrupted"
        assert child.wait(timeout=30) == 0
    finally:
        child.kill()
