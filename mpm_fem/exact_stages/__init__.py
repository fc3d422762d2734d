"""The exact stages of the error budget: each MPM stage replaced by its exact counterpart.

The public names the MPM step and the problems use: :class:`ExactFields` (what a problem's exact
solution provides), :class:`GridData` (the grid stage's nodal sums), :class:`ExactGridStage` (the
grid stage with any of the projection, the mass and the interpolation made exact), :class:`FieldStages`
(the exact stages on a problem's fields as the numpy step takes them, the protocol
:class:`mpm_fem.core.step.ExactStages`).

The modules, one concept each (:mod:`~mpm_fem.exact_stages.stage` states the exact forms):

    fields        the protocol :class:`ExactFields` the problems implement
    grid_data     :class:`GridData` and the nodal values solved from it
    quadrature    the composite Gauss-Legendre rule split at nodes, half cells and breakpoints
    projection    the exact projection: nodal sums of the exact fields on that rule
    mass          the exact mass stage: FE mass matrices of the exact density (scikit-fem)
    stage         :class:`ExactGridStage`, the grid stage of a step with exact stages, and
                  :class:`FieldStages`, the exact stages the numpy step is handed
    grid_kernels  the compiled sums of the quadrature, the projection, the FE mass and the stage
    kernels       the compiled point values of Riemann solutions (:mod:`mpm_fem.problems.sod`)

Nothing here imports :mod:`mpm_fem.problems`: the problems implement :class:`ExactFields` beside
their set-ups and import this package.
"""

from mpm_fem.exact_stages.fields import ExactFields
from mpm_fem.exact_stages.grid_data import GridData
from mpm_fem.exact_stages.stage import ExactGridStage, FieldStages

__all__ = ["ExactFields", "ExactGridStage", "FieldStages", "GridData"]
