"""One loop for every sweep: independent tasks over a list of values, serial or on any executor.

``sweep_map(task, values, executor=..., progress=...)`` returns ``[task(v) for v in values]`` in input
order.  ``executor`` is anything with ``concurrent.futures``' ``submit`` (a thread or process pool, or a
Dask cluster's ``distributed.Client(...).get_executor()``); ``progress`` is ``True`` for a tqdm bar (a
warning names ``pip install tqdm`` when it is missing) or a callable ``progress(index, value, result)``
called as each task finishes (completion order with an executor).  Used by :func:`lindstedt.nnm_sweep`,
:func:`lindstedt.validate.backbone`, the fitted orders of :mod:`lindstedt.validate` and the
forced-response families.

The sweep honours the :mod:`lindstedt.limits` block it runs in: a checkpoint before each task (serial) or as
each one finishes (executor: the tasks not started are then cancelled), and tasks on a thread pool run in a copy
of the caller's context, so their own checkpoints see the same budget, cancel event and progress callback
(a process pool or a Dask cluster does not carry the block to its workers).
"""

from __future__ import annotations

import contextvars
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Iterable, Sequence, TypeVar

from ._budget import checkpoint, tqdm_or_warn

__all__ = ["sweep_map"]

Result = TypeVar("Result")


def _reporter(progress: Any, total: int, description: str) -> tuple[Callable[[int, Any, Any], Any], Callable[[], Any]]:
    """(report, close): nothing, the user's callable, or a tqdm bar."""
    if progress is None or progress is False:
        return (lambda *_: None), (lambda: None)
    if callable(progress):
        return progress, (lambda: None)
    tqdm = tqdm_or_warn()
    if tqdm is None:
        return (lambda *_: None), (lambda: None)
    bar = tqdm(total=total, desc=description, unit="point")
    return (lambda *_: bar.update(1)), bar.close


def sweep_map(
    task: Callable[[Any], Result],
    values: Iterable[Any],
    *,
    executor: Any = None,
    progress: bool | Callable[[int, Any, Any], Any] | None = None,
    description: str = "sweep",
) -> list[Result]:
    """``[task(v) for v in values]``, on ``executor`` when given, reporting ``progress``.

    ``task`` must be picklable for a process pool or a Dask cluster (a module-level function or a
    ``functools.partial`` of one).  The package's sympy and mpmath computations hold its one lock
    (:data:`lindstedt._precision.LOCK`: mpmath's working precision is one process-wide setting), so on a thread pool
    (or a Dask cluster of threads) they run one at a time, correctly, with little speed-up: use processes.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> seen = []
    >>> with ThreadPoolExecutor(2) as pool:
    ...     squares = sweep_map(abs, [-3, 2, -1], executor=pool, progress=lambda i, v, r: seen.append(i))
    >>> squares, sorted(seen)
    ([3, 2, 1], [0, 1, 2])
    """
    values = list(values) if not isinstance(values, Sequence) else values
    report, close = _reporter(progress, len(values), description)
    results: list[Any] = [None] * len(values)
    try:
        if executor is None:
            for index, value in enumerate(values):
                checkpoint(description, index, len(values))
                results[index] = task(value)
                report(index, value, results[index])
        else:
            from concurrent.futures import as_completed

            threads = isinstance(executor, ThreadPoolExecutor)
            futures = {(executor.submit(contextvars.copy_context().run, task, value) if threads
                        else executor.submit(task, value)): index for index, value in enumerate(values)}
            try:
                for done, future in enumerate(as_completed(futures)):
                    index = futures[future]
                    results[index] = future.result()
                    report(index, values[index], results[index])
                    checkpoint(description, done + 1, len(values))
            except BaseException:
                for future in futures:
                    future.cancel()
                raise
    finally:
        close()
    return results
