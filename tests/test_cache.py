"""The process-wide hierarchy cache: hits for equal problems (exact piecewise included), LRU bound, clear_cache."""

import pytest
import sympy

import lindstedt
from lindstedt import LindstedtPoincare, Oscillator

GAP = "Max(0, u - 1/3)"
GAP_KWARGS = {"a0": 1, "omega0": 1}
#: the bound of the cache, as the public cache_info() reports it (documented: 64 problems)
CACHE_MAXSIZE = lindstedt.cache_info().maxsize


@pytest.fixture(autouse=True)
def empty_cache():
    lindstedt.clear_cache()
    yield
    lindstedt.clear_cache()


def _results(expansion):
    """Everything exact an expansion exposes, as comparable sympy data."""
    order = expansion.order
    waveforms = tuple(expansion.waveform(k).to_expr() for k in range(order + 1))
    shifts = tuple(expansion.contact_angle_correction(k) for k in range(order + 1)) if expansion.is_piecewise else ()
    return expansion.omega, expansion.alpha, waveforms, shifts


def test_public_names_exported():
    assert "clear_cache" in lindstedt.__all__ and "cache_info" in lindstedt.__all__
    info = lindstedt.cache_info()
    assert (info.hits, info.misses, info.size, info.maxsize) == (0, 0, 0, 64)


def test_repeated_exact_gap_request_is_served_from_the_cache():
    first = lindstedt.expand(GAP, order=3, **GAP_KWARGS)
    omega = first.omega
    hierarchy = first._hierarchy
    solved = hierarchy.counters["orders"]
    before = lindstedt.cache_info()
    assert (before.hits, before.misses, before.size) == (0, 1, 1)

    second = lindstedt.expand(GAP, order=3, **GAP_KWARGS)
    after = lindstedt.cache_info()
    assert after.hits == before.hits + 1 and after.misses == before.misses
    assert second._hierarchy is hierarchy
    assert second.omega == omega
    assert hierarchy.counters["orders"] == solved  # nothing re-derived


def test_equal_problems_built_differently_share_one_hierarchy():
    base = lindstedt.expand("a*Max(0, u - b)", order=1, a0=1, omega0=1, params={"a": 2, "b": "1/3"})
    same = [
        lindstedt.expand("a*Max(0, u - b)", order=2, a0="1", omega0=1.0, params={"b": sympy.Rational(1, 3), "a": "2"}),
        lindstedt.expand(Oscillator("a*Max(0,u-b)", a0=1, omega0=1, params={"a": 2, "b": "1/3"}), order=1),
        LindstedtPoincare().expand(Oscillator("a*Max(0, u - b)", a0=1, omega0=1, params={"a": 2, "b": "1/3"}), 3),
    ]
    assert all(expansion._hierarchy is base._hierarchy for expansion in same)
    assert lindstedt.cache_info()[:3] == (3, 1, 1)


def test_different_problems_miss():
    requests = [
        (GAP, GAP_KWARGS),
        ("Max(0, u - 1/4)", GAP_KWARGS),
        (GAP, {"a0": 2, "omega0": 1}),
        (GAP, {"a0": 1, "omega0": 2}),
        (GAP, {**GAP_KWARGS, "normalization": "harmonic"}),
        (GAP, {**GAP_KWARGS, "numeric": True}),
        (GAP, {**GAP_KWARGS, "numeric": True, "precision": 40}),
        ("Max(0, u - b)", {**GAP_KWARGS, "params": {"b": "1/3"}}),  # same f after substitution, other problem data
        ("u**3", GAP_KWARGS),
        ("u**3", {}),
    ]
    hierarchies = [lindstedt.expand(f, order=1, **kwargs)._hierarchy for f, kwargs in requests]
    assert len({id(h) for h in hierarchies}) == len(requests)
    info = lindstedt.cache_info()
    kept = len(requests) - 2  # the two numeric=True gaps: float hierarchies of polynomial pieces are not kept
    assert (info.hits, info.misses, info.size) == (0, kept, kept)


def test_float_hierarchies_of_polynomial_pieces_are_derived_afresh_and_agree():
    """numeric=True on a gap is not kept (a sweep would turn the cache over at every value); a contact law's
    float hierarchy (a stretched arc, seconds at high order) is; the values do not depend on it."""
    first = lindstedt.expand(GAP, order=3, numeric=True, **GAP_KWARGS)
    again = lindstedt.expand(GAP, order=3, numeric=True, **GAP_KWARGS)
    assert first._hierarchy is not again._hierarchy and first.omega == again.omega
    assert lindstedt.cache_info().size == 0
    hertz = [lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, numeric=True) for _ in range(2)]
    assert hertz[0]._hierarchy is hertz[1]._hierarchy and lindstedt.cache_info()[:3] == (1, 1, 1)


def test_orders_share_work_and_match_fresh_results():
    high = lindstedt.expand(GAP, order=4, **GAP_KWARGS)
    low = lindstedt.expand(GAP, order=2, **GAP_KWARGS)
    assert low._hierarchy is high._hierarchy
    high_results = _results(high)  # computes orders 0..4
    low_results = _results(low)  # reads orders 0..2 only
    assert len(low.omega) == 3
    assert high.omega[:3] == low.omega and high.alpha[:3] == low.alpha

    lindstedt.clear_cache()
    fresh_low = lindstedt.expand(GAP, order=2, **GAP_KWARGS)
    assert fresh_low._hierarchy is not high._hierarchy
    assert _results(fresh_low) == low_results
    lindstedt.clear_cache()
    assert _results(lindstedt.expand(GAP, order=4, **GAP_KWARGS)) == high_results


def test_bound_holds_and_least_recently_used_is_evicted():
    def request(k):
        return lindstedt.expand("u**3", order=1, a0=k, omega0=1)._hierarchy  # lazy: nothing computed

    kept = [request(k) for k in range(1, CACHE_MAXSIZE + 1)]
    assert lindstedt.cache_info().size == CACHE_MAXSIZE
    assert request(1) is kept[0]  # touch a0=1: now the most recently used
    for k in range(CACHE_MAXSIZE + 1, CACHE_MAXSIZE + 11):
        request(k)
        assert lindstedt.cache_info().size <= CACHE_MAXSIZE
    assert lindstedt.cache_info().size == CACHE_MAXSIZE
    hits = lindstedt.cache_info().hits
    assert request(1) is kept[0]  # survived: used recently
    assert lindstedt.cache_info().hits == hits + 1
    misses = lindstedt.cache_info().misses
    assert request(2) is not kept[1]  # a0=2 was the least recently used: evicted
    assert lindstedt.cache_info().misses == misses + 1


def test_clear_cache_empties_and_results_are_unchanged():
    expansion = lindstedt.expand(GAP, order=3, **GAP_KWARGS)
    smooth = lindstedt.expand("u**3 + u**5", order=3, normalization="harmonic")
    before = _results(expansion), _results(smooth)
    assert lindstedt.cache_info().size == 2

    assert lindstedt.clear_cache() is None
    info = lindstedt.cache_info()
    assert (info.hits, info.misses, info.size) == (0, 0, 0)

    again = lindstedt.expand(GAP, order=3, **GAP_KWARGS)
    smooth_again = lindstedt.expand("u**3 + u**5", order=3, normalization="harmonic")
    assert again._hierarchy is not expansion._hierarchy
    assert lindstedt.cache_info()[:3] == (0, 2, 2)
    assert (_results(again), _results(smooth_again)) == before
