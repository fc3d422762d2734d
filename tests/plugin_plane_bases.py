"""A basis without a 2D form, for ``test_plane_api.py`` and ``test_plane_cli.py`` (``plugin_plane_bases:Flat``)."""

from mpm_fem.bases.point import Point


class Flat(Point):
    """The P1 hats with the tensor flag off: a 1D basis the 2D step refuses."""

    name = "flat"
    title = "P1 hats, 1D only"
    grid_functions = "flat"
    kernels = None
    tensor = False
