"""The GIL is released around Rust work: another Python thread runs
during a long call."""

import threading
import time

import trilux
from conftest import grid


def progress_during(call):
    count = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    time.sleep(0.05)
    before = count[0]
    start = time.perf_counter()
    call()
    elapsed = time.perf_counter() - start
    during = count[0] - before
    stop.set()
    t.join()
    return during, elapsed


def test_a_second_thread_progresses_during_sampling():
    v, f, _ = grid(32)
    during, elapsed = progress_during(lambda: trilux.sample_surface((v, f), 4_000_000, seed=1))
    assert elapsed > 0.05
    # Holding the GIL, the spinning thread would get a few switch
    # intervals (5 ms each) at most; released, it spins the whole call.
    assert during > 20_000, (during, elapsed)


def test_a_second_thread_progresses_during_blue_noise():
    v, f, _ = grid(32)
    during, elapsed = progress_during(lambda: trilux.blue_noise((v, f), 100_000, seed=1))
    assert during > 20_000, (during, elapsed)


def test_a_second_thread_progresses_during_light_sampling():
    import numpy as np

    v, f, uv = grid(32)
    image = np.random.default_rng(0).uniform(0, 1, (256, 256, 3))
    emitter = trilux.Emitter((v, f), image, uv=uv, strategy="texture-exact")
    during, elapsed = progress_during(lambda: emitter.sample(1_000_000, [0.5, 0.5, 1.0], seed=1))
    assert during > 20_000, (during, elapsed)
