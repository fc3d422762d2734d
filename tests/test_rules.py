"""The rule book (``mpm_fem.measure.claims.rules``) holds every threshold a verdict uses: no numeric
literal that could be a threshold is written anywhere else in the claims package, every rule has a
reason and is read by some criterion, and an unknown rule is refused.

The numeric literals allowed outside the rule book (:data:`ALLOWED`) are the integers 0, 1 and 2:
0 and 1 as indices, starts and counts (``rows[0]``, ``len(x) - 1``, ``1 / factor``, ``1 - tolerance``),
2 only as the two meshes an order is computed between and the two subsets of a stage (``2 ** n``).
Any other number (a float, or an integer above 2) is a threshold and belongs in the rule book. A
number inside a string (a format spec, a docstring) is not a literal."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from mpm_fem.measure.claims import rules
from mpm_fem.measure.claims.rules import RULES, rule

PACKAGE = Path(rules.__file__).parent
#: The numeric literals a criterion may write (module docstring).
ALLOWED = {0, 1, 2}


def _numbers(tree: ast.AST) -> list[tuple[int, object]]:
    """``(line, value)`` of every numeric literal of ``tree`` (booleans are not numbers)."""
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, (int, float, complex))
            and not isinstance(n.value, bool)]


def _is_allowed(value) -> bool:
    return isinstance(value, int) and value in ALLOWED


def _modules():
    return sorted(p for p in PACKAGE.glob("*.py") if p.name != "rules.py")


@pytest.mark.parametrize("path", _modules(), ids=lambda p: p.name)
def test_no_threshold_is_written_outside_the_rule_book(path):
    tree = ast.parse(path.read_text())
    found = [(line, v) for line, v in _numbers(tree) if not _is_allowed(v)]
    assert not found, f"{path.name}: numeric literals outside the rule book (line, value): {found}"


def test_the_walk_finds_a_threshold_written_in_a_criterion():
    """The test above can fail: a literal threshold in a made-up criterion is found, 0, 1, 2 and a
    number inside a string are not."""
    source = ('def c(t):\n    """x > 0.5"""\n'
              '    return t[0] > 0.7 and len(t) - 1 >= 2 and f"{t[1]:.2f}" and t[2] > 1e-3\n')
    found = [v for _, v in _numbers(ast.parse(source)) if not _is_allowed(v)]
    assert found == [0.7, 1e-3]


def _rule_reads() -> set[str]:
    """The names passed to ``rule("...")`` anywhere in the claims package but the rule book."""
    names = set()
    for path in _modules():
        for n in ast.walk(ast.parse(path.read_text())):
            if isinstance(n, ast.Call) and getattr(n.func, "id", "") == "rule":
                names |= {a.value for a in n.args if isinstance(a, ast.Constant)}
            # rule(k) for k in ("A", "B"): the names of a tuple iterated into rule()
            if isinstance(n, ast.comprehension) and isinstance(n.iter, ast.Tuple):
                names |= {e.value for e in n.iter.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
    return names


def test_every_rule_is_read_by_some_criterion():
    unread = set(RULES) - _rule_reads()
    assert not unread, f"rules no criterion reads: {sorted(unread)}"


def test_every_rule_has_a_meaning_a_reason_and_claims():
    for r in RULES.values():
        assert r.meaning and r.reason and r.claims, r.name
        assert isinstance(r.value, (int, float)), r.name


def test_an_unknown_rule_is_refused_and_a_rule_is_defined_once():
    with pytest.raises(KeyError, match="no rule 'NOPE'"):
        rule("NOPE")
    with pytest.raises(ValueError, match="defined twice"):
        rules._add("SEPARATE", 0.5, "m", "r", ("E1",))


def test_one_definition_of_first_order():
    """C1's band, C5-C10's band tolerance and C13's first order are the same tolerance of an order."""
    from mpm_fem.measure.claims import BAND_TOLERANCE, FIRST_ORDER, GLOBAL_ORDER

    tol = rule("ORDER_TOLERANCE")
    assert BAND_TOLERANCE == tol and FIRST_ORDER == pytest.approx(1 - tol)
    assert GLOBAL_ORDER == pytest.approx((1 - tol, 1 + tol))
