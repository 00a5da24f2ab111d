"""Input that once crashed the module or misbehaved (found by an adversarial review): each
must now give a clean answer or a clean error. Crash-prone cases run in a subprocess, so a
crash fails the test instead of ending the suite."""
import collections.abc
import os
import signal
import subprocess
import sys
import textwrap

import cv2
import numpy as np
import pytest

import omnical


def run_child(code, *args, timeout=120):
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code), *map(str, args)], capture_output=True,
                          text=True, timeout=timeout, env=os.environ)


def test_a_missing_codecs_plugin_is_an_input_error_and_projection_still_works(data, tmp_path):
    """OMNICAL_CODECS_PLUGIN names the one image codecs plugin to load: pointing nowhere,
    reading an image raises InputError with the CLI's text; importing and projecting need
    no plugin."""
    missing = tmp_path / "no-plugin.so"
    completed = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import sys
        import omnical
        target, image, sensor = sys.argv[1:]
        # Importing omnical loads none of OpenCV's file codecs.
        assert "libopencv_imgcodecs" not in open("/proc/self/maps").read()
        try:
            omnical.detect(target, [image], threads=1)
        except omnical.InputError as error:
            print(error)
        pixels, status = omnical.Sensor.load(sensor).project([[400.0, -150.0, 60.0]])
        print(omnical.status_name(status[0]))
        """), data / "targets" / "aprilgrid-6x6-30mm.yaml", data / "rendered" / "ohte-sph-near" / "near000.png",
        data / "sensors" / "ohte-sph.yaml"], capture_output=True, text=True, timeout=120,
        env={**os.environ, "OMNICAL_CODECS_PLUGIN": str(missing)})
    assert completed.returncode == 0, completed.stderr
    message, status = completed.stdout.splitlines()
    assert message.startswith(f"OMNICAL_CODECS_PLUGIN: {missing}: no such file; it must name "
                              "libomnical_codecs_plugin.so"), message
    assert status == "ok", status


def test_images_from_a_lazy_sequence_of_temporaries(data):
    """Each __getitem__ returns a new array that nothing else holds: the job must not keep
    pointers into it."""
    paths = sorted((data / "rendered" / "ohte-sph-near").glob("near00[0-2].png"))

    class Lazy(collections.abc.Sequence):
        def __len__(self):
            return len(paths)

        def __getitem__(self, i):
            if i >= len(paths):
                raise IndexError
            return cv2.imread(str(paths[i]), cv2.IMREAD_GRAYSCALE)
    target = data / "targets" / "aprilgrid-6x6-30mm.yaml"
    lazy = omnical.detect(target, Lazy(), threads=2)
    from_files = omnical.detect(target, [str(p) for p in paths], threads=2)
    for a, b in zip(lazy.images, from_files.images):
        np.testing.assert_array_equal(a.ids, b.ids)
        np.testing.assert_array_equal(a.pixels, b.pixels)


def test_a_conversion_that_runs_out_of_memory_raises_memory_error():
    completed = run_child("""
        import numpy as np, omnical, sys
        sensor = omnical.Sensor.load(sys.argv[1])
        try:
            sensor.project(np.broadcast_to(1.0, (3_000_000_000, 3)))
        except MemoryError:
            print("memory error")
    """, os.path.join(os.environ.get("OMNICAL_SOURCE_DIR", "."), "datasets-synthetic/sensors/ohte-sph.yaml"))
    assert completed.returncode == 0 and completed.stdout.strip() == "memory error", completed.stderr


def test_a_daemon_thread_in_a_job_does_not_abort_the_exit(data):
    completed = run_child("""
        import sys, threading, time, omnical
        sensor = omnical.Sensor.load(sys.argv[1])
        threading.Thread(target=lambda: omnical.remap(sensor, "perspective", size=(4000, 3000), n=3, per_pixel=True,
                                                      threads=1, progress=lambda *a: None), daemon=True).start()
        time.sleep(0.5)
    """, data / "sensors" / "ohte-sph-misaligned.yaml")
    assert completed.returncode == 0, completed.stderr


def test_self_containing_parameters_are_refused(data):
    parameters = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml").parameters
    loop = []
    loop.append(loop)
    parameters["camera"]["k1"] = loop
    with pytest.raises(omnical.InputError, match="nested too deeply"):
        omnical.Sensor.from_parameters(parameters)


def test_a_huge_thread_count_is_cut_not_fatal(data):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    many = omnical.remap_tables(sensor, "panorama", size=(50, 20), infinity=True, threads=100000)
    one = omnical.remap_tables(sensor, "panorama", size=(50, 20), infinity=True, threads=1)
    np.testing.assert_array_equal(many[0], one[0])


def test_a_callback_whose_answer_cannot_be_read_reaches_the_caller(data):
    class Unreadable:
        def __bool__(self):
            raise ValueError("no truth here")
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    with pytest.raises(ValueError, match="no truth here"):
        omnical.remap(sensor, size=(40, 10), n=3, progress=lambda *a: Unreadable())


def test_ignored_sigint_stays_ignored_and_no_stale_interrupt_remains(data):
    completed = run_child("""
        import os, signal, sys, threading, omnical
        sensor = omnical.Sensor.load(sys.argv[1])
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        sent = []
        def progress(stage, done, total):
            if not sent:
                sent.append(os.kill(os.getpid(), signal.SIGINT))
        omnical.remap(sensor, size=(200, 50), n=3, threads=1, progress=progress)
        print("ignored")
        signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            omnical.remap(sensor, size=(4000, 1000), n=3, per_pixel=True, threads=1,
                          progress=lambda *a: sent.append(None) if len(sent) > 1 else sent.append(os.kill(os.getpid(), signal.SIGINT)))
        except KeyboardInterrupt:
            print("interrupted")
        result = []
        worker = threading.Thread(target=lambda: result.append(omnical.remap_tables(sensor, size=(40, 10), n=3)))
        worker.start(); worker.join()
        print("thread ok" if result else "thread failed")
    """, data / "sensors" / "ohte-sph.yaml")
    assert completed.stdout.splitlines() == ["ignored", "interrupted", "thread ok"], completed.stderr
    assert completed.returncode == 0


def test_bad_values_that_once_slipped_through(data, tmp_path):
    with pytest.raises(omnical.InputError, match="spacing_ratio: must be a finite number"):
        omnical.Target.aprilgrid(6, 6, 30.0, float("inf"))
    with pytest.raises(omnical.InputError, match="path contains a NUL character"):
        omnical.Sensor.load(str(data / "sensors" / "ohte-sph.yaml") + "\0junk")
    target = data / "targets" / "aprilgrid-6x6-30mm.yaml"
    detections = omnical.detect(target, [data / "rendered" / "ohte-sph-near" / "near000.png"])
    with pytest.raises(omnical.InputError, match="^fixed: expected block names"):
        omnical.calibrate(target, detections=detections, fixed=5)
    with pytest.raises(omnical.InputError, match="^detection_passes: must be 1..5"):
        omnical.calibrate(target, detections=detections, detection_passes=10**6)
    with pytest.raises(omnical.InputError, match="the corners were found on another board"):
        omnical.calibrate(data / "targets" / "aprilgrid-6x6-88mm.yaml", detections=detections)
    image = cv2.imread(str(data / "rendered" / "ohte-sph-near" / "near000.png"))
    with pytest.raises(omnical.InputError, match="^maps: expected"):
        omnical.unwarp(image, (np.zeros((0, 0)), np.zeros((0, 0))))
    # Found by the 2026-11-25 fuzzing: a step of 0.01 px or 1e9 samples ran for minutes, a
    # distance of 1e300 mm overflowed into an internal error, both distances were not named.
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    with pytest.raises(omnical.InputError, match="^step_px: must be 1 to 1000$"):
        omnical.diff(sensor, sensor, step_px=0.01)
    with pytest.raises(omnical.InputError, match="profile_samples: must be 4 to 100000$"):
        omnical.design_fit(profile="sphere", profile_samples=10**9)
    with pytest.raises(omnical.InputError, match="characteristic_samples: must be 2 to 100000$"):
        omnical.design_fit(profile="sphere", characteristic_samples=10**9)
    with pytest.raises(omnical.InputError, match="^distance_mm: the object distance must be at most 1e8 mm"):
        omnical.export_central(sensor, distance_mm=1e300)
    with pytest.raises(omnical.InputError, match="^n: give only one of distance_mm and n$"):
        omnical.parallax(sensor, n=5, distance_mm=100)


def test_ctrl_c_reaches_a_main_thread_call_while_another_thread_works(data):
    completed = run_child("""
        import os, signal, sys, threading, time, omnical
        sensor = omnical.Sensor.load(sys.argv[1])
        started = threading.Event()
        def background():
            omnical.remap(sensor, size=(2000, 1500), n=3, per_pixel=True, threads=1,
                          progress=lambda *a: started.set())
        worker = threading.Thread(target=background, daemon=True)
        worker.start()
        started.wait()
        threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        start = time.monotonic()
        try:
            omnical.remap(sensor, "panorama", size=(8192, 4096), n=7, per_pixel=True, threads=1)
            print("finished")
        except KeyboardInterrupt:
            print(f"interrupted {time.monotonic() - start:.1f}")
    """, data / "sensors" / "ohte-sph-misaligned.yaml")
    words = completed.stdout.split()
    # The main-thread table takes ~11 s alone; the interrupt at 0.5 s must end it early.
    assert words[0] == "interrupted" and float(words[1]) < 5.0, (completed.stdout, completed.stderr)
