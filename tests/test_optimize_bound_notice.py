"""optimize's summary says when the optimum sits on a bound of a variable's range
(issue 23 item 7: c = 400 = its upper bound in the explore.md example)."""

from types import SimpleNamespace

from drymount.design.report_optimize import BOUND_RTOL, bound_notices


def _var(name, lower, upper, is_list=False):
    return SimpleNamespace(name=name, lower=lower, upper=upper, is_list=is_list)


def test_a_value_on_a_bound_is_named_with_the_bound():
    space = SimpleNamespace(variables=(_var("c", 50.0, 400.0), _var("n0", 0.5, 120.0),
                                       _var("lam", 0.0, 1.0, is_list=True)))
    notes = bound_notices(space, (400.0, 26.4, 1.0))
    assert len(notes) == 1
    assert "`c` = 400 is at its upper bound 400" in notes[0]
    # just inside the tolerance of the lower bound, and just outside it
    near = 0.5 + 0.5 * BOUND_RTOL * 119.5
    assert "lower bound 0.5" in bound_notices(space, (200.0, near, 0.0))[0]
    assert bound_notices(space, (200.0, 0.5 + 2 * BOUND_RTOL * 119.5, 0.0)) == []
