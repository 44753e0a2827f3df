"""A pool process under CUTROOM_JOB_MEMORY_MB (``tasks.limit_job_memory``) still does
matrix products once a job holds part of its allowance.

OpenBLAS starts its threads and maps its work buffer on a process's first product; under
the address-space limit, with a job already holding memory, that failed and OpenBLAS
waited for good, so the job after a failed one hung instead of running. Each case runs in
a forked process, as a pool process is, and is ended if it does not finish in time.
"""

import os
import signal
import time

import numpy as np
import pytest

from segmentation import tasks


def in_a_limited_child(settings, held_mb, work):
    """Exit status of a forked child that applies the job limit, holds ``held_mb`` MB, then
    does ``work``; None when it had not finished after 20 s."""
    settings.CUTROOM_JOB_MEMORY_MB = 40
    settings.CUTROOM_CONVERT_WORKER = False
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        status = 1
        try:
            tasks.limit_job_memory()
            held = np.ones(held_mb * 2**17)
            work()
            status = 0 if held.any() else 3
        except MemoryError:
            status = 2
        finally:
            os._exit(status)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status)
        time.sleep(0.05)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    return None


def numpy_product():
    a = np.random.default_rng(0).random((1000, 60))
    assert (a @ a.T).shape == (1000, 1000)


def scipy_product():
    import scipy.linalg

    a = np.random.default_rng(0).random((300, 300))
    scipy.linalg.solve(a + 300 * np.eye(300), np.ones(300))


def faiss_search():
    import faiss

    index = faiss.IndexFlatL2(32)
    index.add(np.random.default_rng(0).random((2000, 32), dtype="float32"))
    index.search(np.random.default_rng(1).random((100, 32), dtype="float32"), 5)


@pytest.mark.parametrize("work", [numpy_product, scipy_product, faiss_search])
def test_a_product_runs_with_part_of_the_allowance_held(settings, work):
    assert in_a_limited_child(settings, 20, work) == 0


def test_past_the_allowance_a_job_meets_a_memory_error(settings):
    # Well past it: a test process may run tests on a thread whose malloc arena has up to
    # 64 MB of address space reserved already, which a forked child can fill without asking
    # for more (a pool process runs its jobs on its main thread).
    assert in_a_limited_child(settings, 200, numpy_product) == 2
