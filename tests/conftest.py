"""Fixtures shared by the test modules."""

import pytest

import mpm_fem.fused as fused_module


@pytest.fixture
def loop_steps(monkeypatch):
    """Counts the steps the compiled loop takes (the rest go through FusedStep.step)."""
    taken = []
    advance = fused_module.FusedStep.advance

    def counting(self, *args, **kwargs):
        out = advance(self, *args, **kwargs)
        taken.append(out[2])
        return out

    monkeypatch.setattr(fused_module.FusedStep, "advance", counting)
    return taken


# ------------------------------------------------------------------ the schedule of the two workers
# Most of the fast set's time is numba compiling the fused kernel's variants, once per process for
# each (basis, model, scheme, remedies) a test takes. pytest-xdist runs with `--dist loadgroup`
# (pyproject.toml): a unit of work is a module, as with `--dist loadscope` (a module-scoped fixture
# runs once), except that the modules that step every basis are split by the test's basis, whose
# variants share no compiled code, so the two workers compile different bases side by side instead
# of one worker compiling all four while the other idles. The units that compile most go first
# (`--no-loadscope-reorder` keeps this order); the rest follow in collection order.
SPLIT_BY_BASIS = ("test_fused.py", "test_budget.py")
FIRST = ("test_fused.py[bspline_gimp]", "test_fused.py[gimp]", "test_fused.py[bspline]", "test_budget.py[bspline_gimp]",
         "test_fused_remedies.py", "test_reproduce.py", "test_burgers_study.py", "test_fused.py[mpm]",
         "test_budget.py[mpm]", "test_fused_loop.py")


def _unit(item) -> str:
    """The test's unit of work: its module, or with the module's split its module and basis."""
    module = item.path.name
    params = getattr(getattr(item, "callspec", None), "params", {})
    if module in SPLIT_BY_BASIS and "basis" in params:
        return f"{module}[{params['basis']}]"
    return module


def pytest_collection_modifyitems(config, items):
    units = [_unit(item) for item in items]
    rank = {unit: k for k, unit in enumerate(FIRST)}
    for item, unit in zip(items, units):
        item.add_marker(pytest.mark.xdist_group(unit))
    order = sorted(range(len(items)), key=lambda k: (rank.get(units[k], len(FIRST)), k))
    items[:] = [items[k] for k in order]
