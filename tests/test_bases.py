"""The bases behind their contract (mpm_fem.bases): the registry, the completeness check, each
basis's compiled row against its numpy rows, and the fused step that names no basis."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

import mpm_fem.fused as fused
from mpm_fem.bases import Basis, IncompleteBasisError, Kernels, get, names, register
from mpm_fem.bases.point import Point
from mpm_fem.bases.registry import _BASES
from mpm_fem.core.grid import grid_from_nodes, uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.shape import basis_integrals, make_shape
from mpm_fem.core.step import Stages, Walls


def test_the_registry_lists_the_five_bases_and_refuses_an_unknown_name_listing_the_known():
    assert names() == ("mpm", "gimp", "bspline", "bspline_gimp", "cubic")
    assert all(get(name).name == name and get(get(name)) is get(name) for name in names())
    with pytest.raises(ValueError,
                       match="unknown basis 'quartic'; choose one of mpm, gimp, bspline, bspline_gimp, cubic"):
        get("quartic")
    with pytest.raises(ValueError, match="unknown basis"):
        make_shape(uniform_grid(0.0, 1.0, 0.1), np.array([0.5]), basis="quartic")
    with pytest.raises(ValueError, match="unknown basis 'quartic'"):
        Stages(basis="quartic")


def test_each_basis_names_a_registered_point_basis_and_particle_domain_twin():
    """Each basis names its point basis and its particle-domain twin; a point basis without a
    particle-domain basis over its functions yet (the cubic B-splines) names itself, and the grid
    volume reset, which needs the twin, is refused for it."""
    for basis in map(get, names()):
        functions, twin = get(basis.grid_functions), get(basis.domain_twin)
        assert not functions.domain and functions.grid_functions == functions.name, basis
        assert twin.grid_functions == basis.grid_functions and twin.domain_twin == twin.name, basis
        assert twin.domain or twin is basis, basis
        assert (basis.name == functions.name) != basis.domain, basis
        if not twin.domain:
            with pytest.raises(ValueError, match=f"the basis {basis.name} has no particle-domain twin"):
                Stages(basis=basis.name, volume="grid")
    assert [b for b in names() if not get(get(b).domain_twin).domain] == ["cubic"]


class _Cubic(Point):
    """A point basis under a new name, for the registration checks (not registered)."""

    name = "cubic_test"


def _without(cls, **changed):
    """A subclass of ``cls`` with the class attributes ``changed`` (``None``: removed)."""
    return type("Changed", (cls,), changed)


@pytest.mark.parametrize(("change", "piece"), [
    ({"width": None}, "width (the nodes per particle a row starts with)"),
    ({"degree": 2.0}, "degree (the polynomial degree"),
    ({"domain_twin": None}, "domain_twin (the particle-domain basis of the grid volume reset)"),
    ({"kernels": Point.kernels._replace(project=None)}, "kernels.project (a compiled function)"),
    ({"kernels": Point.kernels._replace(row=lambda *a: a)}, "kernels.row (a compiled function)"),
    ({"domain": True}, "kernels.scalars (a compiled function); kernels.column (a compiled function)"),
    ({"kernels": (1, 2, 3)}, "kernels (its compiled Kernels, or None: the numpy step only)"),
])
def test_registration_refuses_a_basis_missing_a_piece_and_names_the_piece(change, piece):
    incomplete = _without(_Cubic, **change)()
    with pytest.raises(IncompleteBasisError, match=re.escape(piece)):
        register(incomplete)
    assert "cubic_test" not in names()


def test_registration_refuses_a_basis_without_numpy_rows_or_base_class_and_a_name_taken():
    class NoShape(Basis):
        name, title, width, grid_functions, domain, domain_twin, degree, uniform = (
            "noshape", "none", 2, "noshape", False, "gimp", 1, False)
        kernels = Point.kernels

        def integrals(self, grid):
            return grid.lumped_mass

    with pytest.raises(TypeError, match="abstract method shape"):
        NoShape()  # the base class refuses it before the registry sees it
    with pytest.raises(IncompleteBasisError, match="the base class Basis"):
        register(object())
    with pytest.raises(ValueError, match="registered already"):
        register(_without(_Cubic, name="gimp")())
    assert names() == ("mpm", "gimp", "bspline", "bspline_gimp", "cubic")


def test_a_complete_basis_registers_and_is_read_everywhere_by_its_name(monkeypatch):
    monkeypatch.setitem(_BASES, "cubic_test", None)  # restored (removed) after the test
    del _BASES["cubic_test"]
    register(_Cubic())
    grid = uniform_grid(0.0, 1.0, 0.1)
    x = np.array([0.05, 0.5])
    assert np.array_equal(make_shape(grid, x, basis="cubic_test").S, make_shape(grid, x).S)
    assert np.array_equal(basis_integrals(grid, "cubic_test"), grid.lumped_mass)
    assert Stages(basis="cubic_test").basis == "cubic_test"


def _rows(kernel, grid, x, V, K, inv_spacing):
    """Each particle's cell and row from a basis's compiled ``row`` kernel, ``K`` columns (those a
    point basis leaves unwritten stay 0)."""
    h = np.ascontiguousarray([grid.h, 1.0 / grid.h])
    rows, S, G = np.zeros((x.size, K), np.intp), np.zeros((x.size, K)), np.zeros((x.size, K))
    cells = np.empty(x.size, np.intp)
    for q in range(x.size):
        cells[q], need = kernel(grid.nodes, h, inv_spacing, x[q], V[q], rows[q], S[q], G[q])
        assert need <= K
    return cells, rows, S, G


def _dense(grid, rows, W):
    """The (n_p, n_nodes) matrix of a row's weights, duplicates summed."""
    out = np.zeros((rows.shape[0], grid.n_nodes))
    np.add.at(out, (np.repeat(np.arange(rows.shape[0]), rows.shape[1]), rows.ravel()), W.ravel())
    return out


@pytest.mark.parametrize("basis", names())
def test_the_compiled_row_is_the_numpy_row_bit_for_bit_in_the_node_arithmetic(basis):
    """Each basis's compiled ``row`` with ``inv_spacing = 0`` (the node arithmetic) gives its numpy
    rows bit for bit: on a stretched grid, or (a basis needing equal cells) on a grid whose cells
    agree to 1e-10. On a uniform grid with ``inv_spacing = 1/h`` (uniform-grid arithmetic) it
    agrees to round-off."""
    b = get(basis)
    rng = np.random.default_rng(4)
    nodes = (np.linspace(0.0, 1.0, 21) + 2e-12 * rng.uniform(-1, 1, 21) if b.uniform
             else np.cumsum(np.r_[0.0, rng.uniform(0.5, 1.5, 20)]))
    grid = grid_from_nodes(nodes)
    x = np.concatenate([rng.uniform(nodes[0], nodes[-1], 500), nodes])
    V = rng.uniform(0.2, 1.5, x.size) * grid.h.min()
    want = make_shape(grid, x, V, basis)
    cells, rows, S, G = _rows(b.kernels.row, grid, x, V, want.S.shape[1], 0.0)
    assert np.array_equal(cells, want.cell) and np.array_equal(rows, want.nodes)
    assert np.array_equal(S, want.S) and np.array_equal(G, want.G)
    uniform = uniform_grid(0.0, 1.0, 0.05)
    y, W = (x - nodes[0]) / (nodes[-1] - nodes[0]), V / (nodes[-1] - nodes[0])
    want = make_shape(uniform, y, W, basis)
    _, rows, S, G = _rows(b.kernels.row, uniform, y, W, want.S.shape[1] + 1, 20.0)
    assert np.abs(_dense(uniform, rows, S) - want.matrix().toarray()).max() < 1e-12
    assert np.abs(_dense(uniform, rows, G) - want.matrix(derivative=True).toarray()).max() < 1e-9


def _code(path: Path) -> tuple[set[str], list[str]]:
    """The names a module's code uses and its string literals, docstrings left out."""
    tree = ast.parse(path.read_text())
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef)) and node.body
                  and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant)}
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    used |= {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
    strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
               and id(n) not in docstrings]
    return used, strings


def test_the_fused_step_names_no_basis_and_compares_no_basis_code():
    """``mpm_fem/fused/`` holds no basis's name, code or arithmetic: no registered name in its code
    or prose (``gimp``, ``bspline``, ``B-spline``; the point mass's ``mpm`` as a string), no basis
    code (``POINT``, ``GIMP``, ``BSPLINE``, ``BSPLINE_GIMP``, ``BASIS_CODE``, ``DOMAIN_OF``), no
    comparison with ``BASIS``. A variant takes a basis's kernels as globals (mpm_fem.fused.compiler)."""
    codes = {"POINT", "GIMP", "BSPLINE", "BSPLINE_GIMP", "BASIS_CODE", "DOMAIN_OF", "WIDTH_OF", "DOMAIN_BASES"}
    found = []
    for path in sorted(Path(fused.__file__).parent.glob("*.py")):
        text = path.read_text()
        used, strings = _code(path)
        found += [f"{path.name}: the code {name}" for name in sorted(codes & used)]
        found += [f"{path.name}: the string {s!r}" for s in strings if s in names()]
        found += [f"{path.name}: {m.group(0)!r}" for m in re.finditer(r"(?i)gimp|b-?spline", text)]
        compared = re.finditer(r"\bBASIS\s*[=!]=|[=!]=\s*BASIS\b", text)
        found += [f"{path.name}: a comparison with BASIS" for _ in compared]
    assert not found, "\n".join(found)


def test_an_unknown_basis_never_reaches_the_kernel():
    """A basis reaches a compiled variant only by its registered name: an unknown name is refused by
    the stages and by the fused step, and the compiler refuses a basis that is not the registered
    one (an integer code, an unregistered instance) before compiling anything."""
    from mpm_fem.fused.compiler import PASSES, _basis_globals
    from mpm_fem.fused.project import _project

    grid = uniform_grid(0.0, 1.0, 0.1)
    with pytest.raises(ValueError, match="unknown basis"):
        fused.FusedStep(grid, IdealGas(), Walls(), Stages(basis="quartic"))
    for bad in (0, 3, "gimp", _Cubic(), object()):
        with pytest.raises(ValueError, match="registered basis"):
            _basis_globals({"BASIS": bad})
        with pytest.raises(ValueError, match="registered basis"):
            PASSES[False].get(_project, BASIS=bad, WIDTH=2)
    assert _basis_globals({"BASIS": get("gimp")})["PROJECT_RUN"] is get("gimp").kernels.project


def test_the_kernels_are_a_named_tuple_of_the_contract():
    assert Kernels._fields == ("row", "pass_row", "project", "any_grid", "move", "scalars", "column")
