"""Measurements on what an engine produced: the exponential fit, the steady state of the thermal
network, the regime of the settled motion and the coexisting attractors. The solvers report these for
every run, so this layer sits below them."""
