"""mpm-fem: the error of the Material Point Method, stage by stage, beside fixed-mesh FEM.

Reproduces and extends L.-T. Tran and M. Berzins, "Error Analysis for Material Point Method and a
case study from Gas Dynamics" (slides; the claims and the source's tables: ``docs/claims.md``).
"""

__version__ = "0.1.0"
