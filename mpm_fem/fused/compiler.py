"""The variant compiler: each pass and the loop compiled once per basis, model, width, ... .

A pass reads a few module globals in capitals; a variant is its code with them replaced by constants
(:func:`_compile`), so numba prunes the other models', schemes' and remedies' branches and a variant
holds one basis's kernels only. The replacements:

    global        replaced with                                             in the variants of
    BASIS         a registered basis (:func:`mpm_fem.bases.get`), which     every pass but _update_exact; the loop
                  gives the globals below; the passes read only those
    ROW, SHAPE_ROW, PROJECT_RUN, MOVE_RUN
                  the basis's kernels ``pass_row``, ``row``, ``project``,   every variant with BASIS
                  ``move`` (:class:`mpm_fem.bases.contract.Kernels`)
    STORED        1 if the basis's rows are pass 1's stored ones (a         every variant with BASIS
                  particle-domain basis), else 0
    REGISTERS     1 if the basis has ``move`` (pass 2's sums in registers)  every variant with BASIS
    ANY_GRID      1 if its ``project``, ``move`` serve any grid, else 0     every variant with BASIS
                  (then only a grid uniform to round-off)
    TWIN_ROW, TWIN_SCALARS, TWIN_COLUMN
                  the kernels ``row``, ``scalars``, ``column`` of the       every variant with BASIS
                  basis's ``domain_twin``: the rows the volume reset
                  averages over
    MODEL         the model code (codes.GAS, BURGERS)                       the passes that update; the loop
    WIDTH         K, the nodes per particle (a row's length)                the passes that read rows; the loop
    WEIGHT        codes.PRESSURE, VISCOUS_STRESS or MOMENTUM                _scatter_pass
    SCHEME        codes.USL, USF or MUSL                                    the loop
    XPIC_ON, VOLUME_ON, TAYLOR_ON   0 or 1: whether the loop runs XPIC,     the loop
                  the grid volume reset, the Taylor force
    SWEPT         1: the loop may take the sweep, 0: never (a baseline)     the loop
    PROJECT, MOVE, UPDATE, FINISH, VISCOUS, GAS_FORCE, XPIC, VOLUME, TAYLOR, SWEEP
                  the loop's passes (:meth:`_Passes._loop_passes`), ``None``   the loop
                  where its run takes none (the branch calling it is
                  pruned); SWEEP (:mod:`~mpm_fem.fused.sweep`, ``SWEEP_ON``)
                  where SWEPT, USL and no remedy

Only a registered, complete :class:`~mpm_fem.bases.contract.Basis` reaches a variant
(:func:`_basis_globals`); :func:`_compile` refuses a variant that would leave a global of ``CONSTANTS``
unreplaced (the modules define them as ``None`` placeholders). A variant's name holds its constants and
a digest of :data:`SOURCES`, which keeps numba's on-disk caches apart (numba stamps only its own file).
"""

import hashlib
import inspect
import types
from pathlib import Path

from numba import njit

import mpm_fem.bases as bases
from mpm_fem.bases import Basis, get, names
from mpm_fem.fused.codes import BURGERS, GAS, MOMENTUM, MUSL, PRESSURE, USF, VISCOUS_STRESS
from mpm_fem.fused.loop import _advance
from mpm_fem.fused.passes import _finish, _move, _move_exact, _scatter_pass, _update, _update_exact
from mpm_fem.fused.project import _project
from mpm_fem.fused.remedies import _taylor_force, _volume_reset
from mpm_fem.fused.sweep import _sweep

LOOP_PASSES = ("PROJECT", "MOVE", "UPDATE", "FINISH", "VISCOUS", "GAS_FORCE", "XPIC", "VOLUME", "TAYLOR", "SWEEP",
               "SWEEP_ON")
BASIS_GLOBALS = ("ROW", "SHAPE_ROW", "PROJECT_RUN", "MOVE_RUN", "STORED", "REGISTERS", "ANY_GRID", "TWIN_ROW",
                 "TWIN_SCALARS", "TWIN_COLUMN")
REPLACED = frozenset(("BASIS", "MODEL", "WIDTH", "WEIGHT", "SCHEME", "XPIC_ON", "VOLUME_ON", "TAYLOR_ON", "SWEPT")
                     + BASIS_GLOBALS + LOOP_PASSES)
_SHAPE = ("BASIS", "WIDTH")
_MODEL = ("BASIS", "MODEL", "WIDTH")
CONSTANTS = {  # the constants of each function's variants (the keywords of _Passes.get)
    _project: _SHAPE,
    _scatter_pass: _SHAPE + ("WEIGHT",),
    _update: _MODEL,
    _move: _MODEL,
    _finish: _MODEL,
    _taylor_force: _MODEL,
    _volume_reset: ("BASIS", "MODEL"),
    _move_exact: _SHAPE,
    _update_exact: ("MODEL",),
    _sweep: _MODEL,
    _advance: _MODEL + ("SCHEME", "XPIC_ON", "VOLUME_ON", "TAYLOR_ON", "SWEPT"),
}
# numba's error model where it is not Python's: the sweep's divisions unchecked, so that its update vectorises
ERROR_MODEL = {_sweep: "numpy"}
# the files whose code a variant compiles (inlined helpers included): this package and the bases
SOURCES = sorted(Path(__file__).parent.glob("*.py")) + sorted(Path(inspect.getsourcefile(bases)).parent.glob("*.py"))
DIGEST = hashlib.sha1(b"".join(path.read_bytes() for path in SOURCES)).hexdigest()[:8]


def _basis_globals(constants):
    """The globals a variant with ``BASIS`` takes from its basis (module docstring; none without).
    Raises ``ValueError`` for a ``BASIS`` that is not a registered basis."""
    if "BASIS" not in constants:
        return {}
    basis = constants["BASIS"]
    if not isinstance(basis, Basis) or basis.name not in names() or get(basis.name) is not basis:
        raise ValueError(f"a variant takes a registered basis (mpm_fem.bases.get), not {basis!r}")
    own, twin = basis.kernels, get(basis.domain_twin).kernels
    return dict(ROW=own.pass_row, SHAPE_ROW=own.row, PROJECT_RUN=own.project, MOVE_RUN=own.move,
                STORED=int(basis.domain), REGISTERS=int(own.move is not None), ANY_GRID=int(own.any_grid),
                TWIN_ROW=twin.row, TWIN_SCALARS=twin.scalars, TWIN_COLUMN=twin.column)


def _compile(fn, parallel, passes=None, **constants):
    """``fn`` compiled serial or parallel with ``constants``, the globals derived from them
    (:func:`_basis_globals`) and ``passes`` (the loop's) as compile-time globals. Raises
    ``ValueError`` if ``fn`` reads a replaceable global its variant does not replace."""
    replaced = dict(constants, **_basis_globals(constants), **(passes or {}))
    unset = REPLACED.intersection(fn.__code__.co_names).difference(replaced)
    if unset:
        raise ValueError(f"{fn.__name__} reads {', '.join(sorted(unset))}, which its variant does not replace")
    suffix = "".join(f"_{k.lower()}{v.name if isinstance(v, Basis) else v}" for k, v in constants.items()) + (
        "_parallel" if parallel else "")
    variant = types.FunctionType(fn.__code__, dict(fn.__globals__, **replaced), f"{fn.__name__}{suffix}_{DIGEST}",
                                 fn.__defaults__)
    variant.__qualname__ = variant.__name__
    return njit(cache=True, parallel=parallel, error_model=ERROR_MODEL.get(fn, "python"))(variant)


class _Passes:
    """The compiled variants of one kind of thread use (serial or parallel passes), made on first
    use and kept: ``get(fn, **constants)`` with the constants ``CONSTANTS[fn]`` names."""

    def __init__(self, parallel: bool):
        self.parallel = parallel
        self._made = {}

    def get(self, fn, **constants):
        key = (fn.__name__, tuple(sorted(constants.items())))
        if key not in self._made:
            if set(constants) != set(CONSTANTS[fn]):
                raise ValueError(f"{fn.__name__}'s variants take {', '.join(CONSTANTS[fn])}, "
                                 f"not {', '.join(constants)}")
            passes = None
            if fn is _advance:  # the loop calls this variant's passes, compiled into it; the loop itself is
                passes = self._loop_passes(**constants)  # serial, its passes parallel or not
                constants = dict(constants, THREADED=int(self.parallel))  # a name per variant
            self._made[key] = _compile(fn, False if fn is _advance else self.parallel, passes, **constants)
        return self._made[key]

    def _loop_passes(self, BASIS, MODEL, WIDTH, SCHEME, XPIC_ON, VOLUME_ON, TAYLOR_ON, SWEPT=1):
        """The passes the loop variant with these constants calls: pass 1 and 2 always, USF's update,
        MUSL's last pass, Burgers' viscous force and each remedy's passes only where they run, so a
        plain run compiles none of the remedies."""
        shape = dict(BASIS=BASIS, WIDTH=WIDTH)
        model = dict(shape, MODEL=MODEL)
        scatter = lambda weight: self.get(_scatter_pass, **shape, WEIGHT=weight)  # noqa: E731
        sweep = SWEPT == 1 and SCHEME not in (USF, MUSL) and not (XPIC_ON or VOLUME_ON or TAYLOR_ON)
        return dict(PROJECT=self.get(_project, **shape), MOVE=self.get(_move, **model),
                    SWEEP=self.get(_sweep, **model) if sweep else None, SWEEP_ON=int(sweep),
                    UPDATE=self.get(_update, **model) if SCHEME == USF else None,
                    FINISH=self.get(_finish, **model) if SCHEME == MUSL else None,
                    VISCOUS=scatter(VISCOUS_STRESS) if MODEL == BURGERS else None,
                    GAS_FORCE=scatter(PRESSURE) if VOLUME_ON and MODEL == GAS else None,
                    VOLUME=self.get(_volume_reset, BASIS=BASIS, MODEL=MODEL) if VOLUME_ON else None,
                    XPIC=scatter(MOMENTUM) if XPIC_ON else None,
                    TAYLOR=self.get(_taylor_force, **model) if TAYLOR_ON else None)


PASSES = {parallel: _Passes(parallel) for parallel in (False, True)}  # the variants, by whether they thread
