"""The exact stages of the error budget: each MPM stage replaced by its exact counterpart.

The public names the MPM step and the problems use: :class:`ExactFields` (what a problem's exact
solution provides), :class:`GridData` (the grid stage's nodal sums), :class:`ExactGridStage` (the
grid stage with any of the projection, the mass and the interpolation made exact).
"""

from mpm_fem.exact_stages.stage import ExactFields, ExactGridStage, GridData

__all__ = ["ExactFields", "ExactGridStage", "GridData"]
