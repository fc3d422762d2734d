"""The time loop (:mod:`mpm_fem.run.solve`): a run from ``t = 0`` to ``T``, one step at a time or in
compiled loops.

It sits above the steps it chooses between, the numpy step (:func:`mpm_fem.core.step.explicit_step`)
and the compiled one (:mod:`mpm_fem.fused`), and hands the numpy step the exact stages
(:class:`mpm_fem.exact_stages.FieldStages`); nothing below it imports it. The problems
(:mod:`mpm_fem.problems`) run through it.
"""
