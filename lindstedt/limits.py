"""Bounded work: every request is priced before it runs, and watched while it runs.

A derivation engine behind a notebook, a web form or a batch queue must know what a request costs before it
starts.  Every request that can be long is first priced by a cost model — an :class:`Estimate` of CPU seconds
and memory from what the request holds — and checked against the :class:`Budget` in force; beyond it the
request is refused at once with a :class:`~lindstedt.BudgetError` naming the estimate, what drives it and the
knob to turn:

* an expansion (``lindstedt.expand``; priced by ``lindstedt.expansion_cost``): the order, the breakpoints and
  polynomial degree of f, its symbolic parameters, the working digits, a release with velocity;
* an NNM expansion (``lindstedt.nnm``): degrees of freedom, springs, order;
* a forced periodic orbit or response: the natural periods a period map spans (refused far below resonance);
* continuations and sweeps: bounded by their ``max_points`` and, inside a budget block, stopped at its limits.

While it runs, a request passes checkpoints (between the orders of a hierarchy, between continuation points,
Newton iterations and sweep tasks); inside ``with budget(...)`` each checkpoint

* raises :class:`~lindstedt.BudgetError` once the block has run longer than its ``seconds`` or grown the
  process by more than its ``memory_mb`` (the estimate is a model; this is the guarantee),
* raises :class:`~lindstedt.Cancelled` once the block's ``cancel`` event is set (from another thread, a UI),
* calls the block's ``progress`` callback with a :class:`Progress` (what runs, how far, since when).

A stopped hierarchy keeps the orders it solved (asking again resumes there); a stopped continuation returns
the branch computed so far (``success=False``, the reason in its message).  The defaults (:data:`DEFAULT`:
600 s, 2048 MB) suit interactive use; a service sets strict ones for the process with :func:`set_default` or
per request with :func:`budget`; the command line has ``--budget SECONDS`` and ``--budget-memory MB``.

The cost model's constants were fitted on the benchmark machine (2 cores, ``benchmarks/bench_cost_model.py``
measures every kind of request against its estimate, and a seeded random sample it was not fitted on); there the
measured CPU time lies within a factor :data:`FACTOR` of the estimate.  A machine k times slower takes k times
the estimate: set the budget accordingly.

Examples
--------
>>> import lindstedt
>>> from lindstedt import limits
>>> lindstedt.expansion_cost("Max(0, u - 1/3)", 100, a0=1, omega0=1).seconds > limits.DEFAULT.seconds
True
>>> with limits.budget(seconds=10):
...     lindstedt.expand("Max(0, u - 1/3)", order=30, a0=1, omega0=1)
Traceback (most recent call last):
...
lindstedt._errors.BudgetError: expansion of Max(0, u - 1/3) to order 30: ~... estimated (within a factor 5), above the time budget of 10 s: ...
"""

from . import _budget
from ._budget import *  # noqa: F403 - exactly the names of _budget.__all__

__all__ = list(_budget.__all__)

#: How far a measured cost may lie from its estimate on the benchmark machine, either way: the ratios measured by
#: ``benchmarks/bench_cost_model.py`` (see ``benchmarks/README.md``) lie within it for time and memory.
FACTOR = _budget.FACTOR
#: The budget in force outside any ``with budget(...)`` block until :func:`set_default` changes it: 600 s, 2048 MB.
DEFAULT = _budget.DEFAULT
