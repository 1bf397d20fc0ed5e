"""Ctrl-C: SIGINT during a render raises KeyboardInterrupt within a second, and the
process renders again afterwards."""

import queue
import signal
import subprocess
import sys
import threading
import time

# The child answers SIGINT as an interactive Python does, however the test runner was
# started: a shell starts background jobs with SIGINT ignored, Python then installs no
# handler of its own, and the signal would do nothing.
CHILD = r"""
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)
import hairtrace
scene = hairtrace.Scene.demo("furball")
started = []
def progress(done, total):
    if not started:
        started.append(1)
        print("rendering", flush=True)
try:
    scene.render(progress=progress, width=640, height=480, spp=4096)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
image = scene.render(width=32, height=24, spp=1)
print("usable", image.shape, flush=True)
"""


def test_sigint_raises_keyboard_interrupt_within_a_second_and_the_process_goes_on():
    child = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True)
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(l.strip()) for l in child.stdout], daemon=True).start()
    try:
        assert lines.get(timeout=30) == "rendering"
        time.sleep(0.3)
        child.send_signal(signal.SIGINT)
        sent = time.monotonic()
        # Uninterrupted, the render would take minutes.
        line = lines.get(timeout=10)
        waited = time.monotonic() - sent
        assert line == "interrupted", line
        assert waited < 1.0, f"{waited:.2f} s"
        assert lines.get(timeout=30) == "usable (24, 32, 3)"
        assert child.wait(timeout=30) == 0
    finally:
        child.kill()
