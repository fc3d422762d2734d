"""The fused step's codes and named indices.

Compile-time codes: each compiled variant (:mod:`mpm_fem.fused.compiler`) freezes one model, scheme
and scatter weight as integer globals, so the branches of the others drop out (a basis comes as its
kernels, :mod:`mpm_fem.bases`). Named indices: the columns of the particle state ``state[cur, IX ..
IP]``, of the model constants ``consts[IGM1 .. IXPIC]`` and of the loop's nodal scratch, so that no
kernel reads a bare column number.
"""

# the models
GAS, BURGERS = 0, 1

# the update schemes
USL, USF, MUSL = range(3)
SCHEME_CODE = {"usl": USL, "usf": USF, "musl": MUSL}

# the weights of the scatter pass (mpm_fem.fused.passes._scatter_pass)
PRESSURE, VISCOUS_STRESS, MOMENTUM = range(3)

# the particle state's columns: state[cur, IX, :n] is x_p, and so on (x, v, V, m, rho, eps, p)
IX, IV, IVOL, IM, IRHO, IE, IP = range(7)
FIELDS = ("x", "velocity", "volume", "mass", "density", "energy", "pressure")  # Particles' names, IX .. IP

# consts[k]: the gas's gamma - 1, gamma (gamma - 1), linear and quadratic artificial viscosity (0 for
# Burgers); Burgers' viscosity eps (0 for the gas); the PIC/FLIP blend (1: FLIP); XPIC's order m (0: off)
IGM1, IGGM1, ILIN, IQUAD, IEPS, IFLIP, IXPIC = range(7)

# rows of the loop's nodal scratch (Scratch.grid): m_i, P_i, F_i, v_i, a_i, v_i^{n+1} and MUSL's P_i always;
# XPIC's P, term, v* and target after them where it runs; the volume reset's V_i and ratio after those
GM, GP, GF, GV, GA, GVN, GPMUSL = range(7)  # GM .. GF: pass 1's three sums, as a basis's project kernel writes them
GPX, GTERM, GVSTAR, GTARGET = range(7, 11)
