"""Long calls release the GIL: another Python thread runs while they work.

Not timed: with a switch interval of 1000 s the interpreter never takes the GIL
from a running thread, so the main thread, woken by the worker just before its
calls, can run only when a call releases the GIL. The worker repeats the call
(up to `REPEAT` times) until the main thread has run; the main thread then sees
the worker unfinished. Calls that kept the GIL would all return first, and the
main thread would see the worker done. (Repeating covers the one race: a call
so short that it takes the GIL back before the woken main thread gets to it.)
"""

from __future__ import annotations

import sys
import threading

import numpy as np
import pytest
from test_mesh import soup

import proxima


REPEAT = 200


def released_during(call) -> bool:
    started, done, main_ran = threading.Event(), threading.Event(), threading.Event()

    def worker():
        started.set()
        for _ in range(REPEAT):
            call()
            if main_ran.is_set():
                break
        done.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        started.wait()
        released = not done.is_set()
        main_ran.set()
    finally:
        sys.setswitchinterval(old)
    t.join()
    assert done.is_set()
    return released


def test_the_check_sees_a_call_that_keeps_the_gil():
    # sum() over a list is one C call that never releases the GIL.
    data = list(range(100_000))
    assert not released_during(lambda: sum(data))


@pytest.fixture(scope="module")
def scene():
    rng = np.random.default_rng(3)
    c = rng.uniform(0, 100, (20_000, 3))
    r = rng.uniform(0.5, 2.0, 20_000)
    v, f = soup(rng, 500, size=0.2)
    return c, r, proxima.Index(c, r), proxima.Mesh(v, f), v, f


def test_long_calls_release_the_gil(scene):
    c, r, idx, mesh, v, f = scene
    q = np.column_stack([c[:500], np.full(500, 3.0)])
    rays = np.column_stack([c[:500], np.ones((500, 3))])
    poses = np.tile(np.eye(4), (50, 1, 1))
    calls = {
        "Index()": lambda: proxima.Index(c, r),
        "insert_many": lambda: proxima.Index(kind="hashgrid", r_max=2.0).insert_many(c, r),
        "update_many": lambda: idx.update_many(None, c),
        "pairs": lambda: idx.pairs(),
        "query_spheres": lambda: idx.query_spheres(q),
        "query_rays": lambda: idx.query_rays(rays),
        "ray_first": lambda: idx.ray_first(rays),
        "Mesh()": lambda: proxima.Mesh(v, f),
        "collide": lambda: proxima.collide(mesh, mesh, poses),
        "cast_rays": lambda: mesh.cast_rays(rays / 100),
        "pairs(workers=2)": lambda: idx.pairs(workers=2),
    }
    kept = [name for name, call in calls.items() if not released_during(call)]
    assert kept == []
