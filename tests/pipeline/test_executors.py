"""Executors: every item comes back exactly once, failures and crashes stay local.

The tasks are fakes (tests/pipeline/dataset_fakes.py) so these tests need no renderer; the
real pipeline runs in test_pipeline.py.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

from spectrinsic.errors import DatasetError, SpectrinsicError
from spectrinsic.pipeline.executors import (
    DaskExecutor,
    ProcessExecutor,
    SerialExecutor,
    WorkerCrashedError,
    choose_executor,
    make_executor,
)

HERE = Path(__file__).resolve().parent
#: Seconds to wait for a Dask worker to start a task before giving up.
START_TIMEOUT_S = 60.0


@pytest.fixture(scope="module")
def fakes(tmp_path_factory: pytest.TempPathFactory):
    """The fake task module, importable by name here and in spawned/Dask worker processes."""
    sys.path.insert(0, str(HERE))
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = str(HERE) + (os.pathsep + old if old else "")
    import dataset_fakes

    yield dataset_fakes
    sys.path.remove(str(HERE))
    if old is None:
        del os.environ["PYTHONPATH"]
    else:
        os.environ["PYTHONPATH"] = old


def _results(pairs):
    return {item.index: outcome for item, outcome in pairs}


def test_serial_failure_does_not_stop_others(fakes, tmp_path):
    items = [fakes.FakeItem(i, str(tmp_path), fail=(i == 1)) for i in range(4)]
    out = _results(SerialExecutor().map_unordered(fakes.square, items))
    assert sorted(out) == [0, 1, 2, 3]
    assert isinstance(out[1], ValueError)
    assert [out[i][0] for i in (0, 2, 3)] == [0, 4, 9]


def test_process_pool_isolates_a_crashing_item(fakes, tmp_path):
    """A worker that dies takes down the pool; only the item it ran is reported as crashed."""
    items = [fakes.FakeItem(i, str(tmp_path), seconds=0.2, crash=(i == 2)) for i in range(6)]
    out = _results(ProcessExecutor(workers=2).map_unordered(fakes.square, items))
    assert sorted(out) == list(range(6))
    assert isinstance(out[2], WorkerCrashedError)
    for i in (0, 1, 3, 4, 5):
        assert out[i][0] == i * i, out[i]
        # ran in a spawned worker, not in this process
        assert out[i][1] != os.getpid()


def test_make_executor_validates():
    assert isinstance(make_executor("serial"), SerialExecutor)
    assert make_executor("process", workers=3).workers == 3
    with pytest.raises(SpectrinsicError, match="did you mean 'process'"):
        make_executor("proces")
    with pytest.raises(SpectrinsicError, match="scheduler"):
        make_executor("dask")
    with pytest.raises(DatasetError, match="unknown executor"):
        make_executor("proces")


def test_executor_policy_serial_local_or_dask():
    """--workers/--threads/--scheduler -> executor, render threads per worker, where it runs."""
    one = choose_executor(cores=8)
    assert isinstance(one.executor, SerialExecutor)
    assert (one.render_threads, one.where) == (None, "this process")  # Dr.Jit uses every core
    assert choose_executor(workers=1, threads=3, cores=8).render_threads == 3
    local = choose_executor(workers=3, cores=8)
    assert isinstance(local.executor, ProcessExecutor) and local.executor.workers == 3
    assert (local.render_threads, local.where) == (2, "3 local worker processes")
    assert choose_executor(workers=4, cores=2).render_threads == 1  # never 0 threads
    assert choose_executor(workers=4, threads=5, cores=2).render_threads == 5
    dask = choose_executor(workers=4, scheduler="tcp://10.0.0.5:8786", cores=8)
    assert (
        isinstance(dask.executor, DaskExecutor) and dask.executor.address == "tcp://10.0.0.5:8786"
    )
    assert (dask.render_threads, dask.where) == (1, "Dask scheduler tcp://10.0.0.5:8786")


def test_dask_retries_the_task_of_a_killed_worker(fakes, tmp_path):
    """Kill a Dask worker while it runs a task: the task is rerun elsewhere, the set completes."""
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    n = 6
    items = [fakes.FakeItem(i, str(tmp_path), seconds=1.0, fail=(i == 5)) for i in range(n)]
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        with distributed.Client(cluster) as client:
            pids = set(client.run(os.getpid).values())
        killed: dict[str, int] = {}

        def kill_a_busy_worker() -> None:
            deadline = time.monotonic() + START_TIMEOUT_S
            while time.monotonic() < deadline:
                for marker in tmp_path.glob("start-*"):
                    _, index, pid = marker.name.split("-")
                    if int(pid) in pids:
                        os.kill(int(pid), signal.SIGKILL)
                        killed.update(index=int(index), pid=int(pid))
                        return
                time.sleep(0.05)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        out = _results(DaskExecutor(cluster.scheduler_address).map_unordered(fakes.square, items))
        killer.join()

    assert killed, "no task started on a worker"
    assert sorted(out) == list(range(n))
    assert isinstance(out[5], ValueError)  # a task's own error is reported, not retried
    for i in range(5):
        assert out[i][0] == i * i, out[i]
    victim = killed["index"]
    if victim != 5:
        # The killed worker started it but never finished it; another worker did.
        assert not (tmp_path / f"done-{victim}-{killed['pid']}").exists()
        assert out[victim][1] != killed["pid"]


def test_process_pool_gives_up_when_workers_cannot_start(fakes, tmp_path):
    """Workers that die before running anything (a failing initializer) end in errors, not in
    an endless resubmission loop."""
    items = [fakes.FakeItem(i, str(tmp_path)) for i in range(3)]
    executor = ProcessExecutor(workers=2, initializer=fakes.failing_initializer)
    out = _results(executor.map_unordered(fakes.square, items))
    assert sorted(out) == [0, 1, 2]
    assert all(isinstance(o, WorkerCrashedError) for o in out.values())
    assert not list(tmp_path.glob("start-*"))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux only")
def test_pool_workers_ask_to_die_with_their_parent(fakes, tmp_path):
    items = [fakes.FakeItem(i, str(tmp_path)) for i in range(2)]
    out = _results(ProcessExecutor(workers=2).map_unordered(fakes.parent_death_signal, items))
    assert set(out.values()) == {signal.SIGKILL}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux only")
def test_kill_9_of_the_parent_kills_busy_workers(fakes, tmp_path):
    """The parent is SIGKILLed while both workers sleep in 600-s tasks: they must go too."""
    import subprocess

    code = f"import dataset_fakes; dataset_fakes.run_sleepers({str(tmp_path)!r})"
    parent = subprocess.Popen([sys.executable, "-P", "-c", code], env=os.environ.copy())
    deadline = time.monotonic() + 120
    while len(list(tmp_path.glob("start-*"))) < 2:
        assert parent.poll() is None and time.monotonic() < deadline, "workers never started"
        time.sleep(0.05)
    pids = [int(p.name.rsplit("-", 1)[1]) for p in tmp_path.glob("start-*")]
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    deadline = time.monotonic() + 60
    while alive := [p for p in pids if _running(p)]:
        assert time.monotonic() < deadline, f"workers {alive} outlived their parent"
        time.sleep(0.05)


def _running(pid: int) -> bool:
    """True while *pid* exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"
