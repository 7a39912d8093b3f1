"""Where the fit's tasks run: in this process, in local worker processes, or on a Dask cluster.

One small interface: ``engine.map(function, items, shared)`` calls ``function(shared, item)``
for every item and returns the results in the order of the items, whatever order they
finish in; ``progress(count)`` hears of finished items and ``each(index, result)`` gets each
result as it arrives; ``chunk_size`` fixes the items per task (default: a few chunks per worker). ``shared`` (the objective, a few hundred kB) travels once per chunk of items
(processes) or once per worker (Dask), not once per item. ``function`` must be a module-level
function. Tasks carry everything they need, seeds included, so every engine returns the
same bits: each task runs with one BLAS thread (a multi-threaded BLAS may sum in another
order) and, in worker processes, one numba thread (the cores are used by the processes).

- :class:`SerialEngine`: this process (``--workers 1``).
- :class:`ProcessEngine`: ``workers`` local processes (``--workers N``; processes, not
  threads, because of the GIL), started with ``spawn`` (numba's thread pool is not safe
  to fork).
- :class:`DaskEngine`: a ``dask.distributed`` cluster (``--scheduler ADDRESS``), e.g.
  ``dask scheduler`` on one machine and ``dask worker ADDRESS --nthreads 1`` on each core's
  worth of the others. A scheduler that does not answer, or has no workers, is an
  :class:`EngineError` after ``timeout_s``, not a hang.

An engine is a context manager. Left normally, it closes (``close``: queued tasks cancelled, the
running ones finished); left by an exception, a Ctrl-C or a SIGTERM (``identification.interrupt``)
included, it stops at once (``abort``): nobody will read the results of its tasks, so local
workers are terminated, not awaited, and a Dask client cancels this command's tasks and closes
(the cluster's scheduler and workers stay). Local workers ignore SIGINT: Ctrl-C in a terminal
reaches the whole process group, and the main process ends them.
"""
from __future__ import annotations

import contextlib
import os
from typing import Callable, Sequence

import numpy as np

from identification.errors import EngineError
from identification.interrupt import deferred, ignore_interrupts, interrupts_held

CHUNKS_PER_WORKER = 4
"""Items are sent in about this many chunks per worker: fewer copies of ``shared``, still
enough chunks to balance starts of unequal cost."""
DEFAULT_TIMEOUT_S = 10.0
POLL_S = 0.05
ABORT_TIMEOUT_S = 3.0
"""How long an aborting engine waits for a terminated worker to exit (then kills it), or for a
Dask client to close."""


WORKER_NICENESS = 10
"""Local workers run this much nicer than the main process (where the OS has niceness): where
both want a core, the main process's work goes first, because it is on the critical path (a
module compiling beside the screening that the stages will wait for, the posterior's sampler),
and the workers take every core the main process leaves idle. Results do not depend on it."""


def start_worker() -> None:
    """A local worker's initializer: interrupts left to the main process
    (``interrupt.ignore_interrupts``) and ``WORKER_NICENESS``."""
    ignore_interrupts()
    if hasattr(os, "nice"):
        with contextlib.suppress(OSError):
            os.nice(WORKER_NICENESS)


def _run_chunk(function: Callable, shared, chunk: Sequence, single_threaded: bool) -> list:
    from threadpoolctl import threadpool_limits
    if single_threaded:
        from fmu_src.kernels.jit import numba
        numba.set_num_threads(1)
    with threadpool_limits(limits=1):
        return [function(shared, item) for item in chunk]


def _report(results: list, first: int, progress, each) -> None:
    if progress:
        progress(len(results))
    if each:
        for offset, result in enumerate(results):
            each(first + offset, result)


def _chunks(items: Sequence, count: int) -> list[list]:
    count = max(1, min(count, len(items)))
    size, extra = divmod(len(items), count)
    out, start = [], 0
    for i in range(count):
        end = start + size + (1 if i < extra else 0)
        out.append(list(items[start:end]))
        start = end
    return out


class SerialEngine:
    """Runs every task here, one after the other."""
    workers = 1
    description = "1 process"

    def map(self, function: Callable, items: Sequence, shared=None, progress: Callable[[int], None] | None = None,
            each: Callable[[int, object], None] | None = None, chunk_size: int | None = None):
        results = []
        for chunk in _chunks(items, -(-len(items) // chunk_size) if chunk_size else max(1, len(items) // 64)):
            done = _run_chunk(function, shared, chunk, single_threaded=False)
            _report(done, len(results), progress, each)
            results += done
        return results

    def close(self):
        """Release the engine after its work is done."""

    def abort(self):
        """Stop now: tasks not yet finished are dropped, not awaited."""
        self.close()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, traceback):
        if exc_type is None:
            self.close()
        else:
            self.abort()


class ProcessEngine(SerialEngine):
    """Runs tasks in ``workers`` local processes."""

    def __init__(self, workers: int):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor
        if workers < 2:
            raise ValueError(f"a process engine needs 2 or more workers, not {workers}")
        self.workers = workers
        self.description = f"{workers} local processes"
        self._pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"),
                                         initializer=start_worker)

    def map(self, function, items, shared=None, progress=None, each=None, chunk_size=None):
        from concurrent.futures import as_completed
        chunks = _chunks(items, -(-len(items) // chunk_size) if chunk_size else self.workers * CHUNKS_PER_WORKER)
        starts = np.cumsum([0] + [len(c) for c in chunks])
        with interrupts_held():    # the first submit starts the workers: see interrupts_held
            futures = {self._pool.submit(_run_chunk, function, shared, chunk, True): i
                       for i, chunk in enumerate(chunks)}
        results: list = [None] * len(chunks)
        for future in as_completed(futures):
            index = futures[future]
            results[index] = future.result()
            _report(results[index], int(starts[index]), progress, each)
        return [result for chunk in results for result in chunk]

    def close(self):
        self._pool.shutdown(cancel_futures=True)

    def abort(self):
        """Cancel the queued tasks and terminate the workers (SIGTERM, then SIGKILL after
        ``ABORT_TIMEOUT_S``): a running task may take a minute, and its result is not wanted."""
        if hasattr(self._pool, "terminate_workers"):     # Python 3.14
            self._pool.terminate_workers()
            processes = []
        else:
            # what terminate_workers does, through the pool's table of its processes
            processes = list((self._pool._processes or {}).values())
            self._pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                process.terminate()
        for process in processes:
            process.join(ABORT_TIMEOUT_S)
            if process.exitcode is None:
                process.kill()
                process.join(ABORT_TIMEOUT_S)
        # the pool's manager thread sees its workers gone and ends: wait for it here, so
        # that the interpreter's exit (which joins it) does not
        self._pool.shutdown(wait=True, cancel_futures=True)


class DaskEngine(SerialEngine):
    """Runs tasks on a ``dask.distributed`` cluster: a scheduler address or a ``Client``."""

    def __init__(self, scheduler, timeout_s: float = DEFAULT_TIMEOUT_S):
        from dask.distributed import Client
        self._own_client = not isinstance(scheduler, Client)
        if self._own_client:
            try:
                self._client = Client(scheduler, timeout=f"{timeout_s}s", set_as_default=False)
            except (OSError, TimeoutError) as exc:
                raise EngineError(f"cannot reach the Dask scheduler at {scheduler!r} within {timeout_s:g} s ({exc}); "
                                  "start one with `dask scheduler` and workers with "
                                  "`dask worker ADDRESS --nthreads 1`") from None
        else:
            self._client = scheduler
        try:
            self._client.wait_for_workers(1, timeout=timeout_s)
            threads = self._client.nthreads()
        except (OSError, TimeoutError):
            self.close()
            raise EngineError(f"the Dask scheduler at {self._client.scheduler.address} has no workers after "
                              f"{timeout_s:g} s; start some with `dask worker ADDRESS --nthreads 1`") from None
        except BaseException:    # Ctrl-C, SIGTERM while waiting: no engine to close later
            self.abort()
            raise
        if any(count > 1 for count in threads.values()):
            self.close()
            raise EngineError(f"the Dask workers of {scheduler!r} run {max(threads.values())} threads each; the fit "
                              "needs single-threaded workers (each task sets its BLAS and numba threads, which is "
                              "not safe between threads): start them with `dask worker ADDRESS --nthreads 1 "
                              "--nworkers N`")
        self.workers = len(threads)
        self.timeout_s = timeout_s
        self.description = f"Dask cluster {self._client.scheduler.address} ({self.workers} workers)"

    def map(self, function, items, shared=None, progress=None, each=None, chunk_size=None):
        # A signal is held while ``shared`` (a few hundred kB) is scattered: interrupted half-way,
        # the scatter would go on in the client's thread and leave a key this command cannot
        # cancel, which the scheduler was seen to keep after the client had closed.
        with deferred():
            shared_future = self._client.scatter(shared, broadcast=True, hash=False)
        chunks = _chunks(items, -(-len(items) // chunk_size) if chunk_size else self.workers * CHUNKS_PER_WORKER)
        starts = np.cumsum([0] + [len(c) for c in chunks])
        futures = []
        try:
            for chunk in chunks:
                futures.append(self._client.submit(_run_chunk, function, shared_future, chunk, True, pure=False))
            index = {future.key: i for i, future in enumerate(futures)}
            for future in self._completed(futures):
                _report(future.result(), int(starts[index[future.key]]), progress, each)
            results = self._client.gather(futures)
        except BaseException:
            # this command's tasks, not anybody else's: the cluster goes on serving its other
            # clients. A client that has lost its scheduler cannot cancel, and has nothing there
            # to cancel: the error to report is the one that brought us here.
            with contextlib.suppress(Exception):
                self._client.cancel(futures + [shared_future])
            raise
        return [result for chunk in results for result in chunk]

    def _completed(self, futures):
        """The futures as they finish; an EngineError when the cluster has had no worker for
        ``timeout_s`` (a lost cluster is an error, not a hang)."""
        import time
        from dask.distributed import as_completed
        finished = as_completed(futures, loop=self._client.loop)
        last_worker_seen = time.monotonic()
        while not finished.is_empty():
            batch = finished.next_batch(block=False)
            yield from batch
            if batch:
                continue
            time.sleep(POLL_S)
            if self._client.nthreads():
                last_worker_seen = time.monotonic()
            elif time.monotonic() - last_worker_seen >= self.timeout_s:
                raise EngineError(f"the Dask cluster at {self._client.scheduler.address} has had no workers "
                                  f"for {self.timeout_s:g} s while {finished.count()} task(s) wait")

    def close(self):
        if self._own_client:
            self._client.close()

    def abort(self):
        """Close this command's client within ``ABORT_TIMEOUT_S`` (its tasks were cancelled
        by ``map``; the scheduler forgets what a closed client wanted); a client given by
        the caller stays open."""
        if self._own_client:
            # the process is ending: a close that fails or times out is not worth a second error
            # (the scheduler forgets a client whose connection closes)
            with contextlib.suppress(Exception):
                self._client.close(timeout=ABORT_TIMEOUT_S)


def make_engine(workers: int | None = None, scheduler=None, timeout_s: float = DEFAULT_TIMEOUT_S):
    """The engine for ``--workers N`` (default: every core here) or ``--scheduler ADDRESS``."""
    if scheduler is not None:
        if workers is not None:
            raise ValueError("give either a number of workers or a Dask scheduler, not both")
        return DaskEngine(scheduler, timeout_s)
    workers = workers if workers is not None else (os.cpu_count() or 1)
    if workers < 1:
        raise ValueError(f"workers = {workers}: give 1 or more")
    return SerialEngine() if workers == 1 else ProcessEngine(workers)
