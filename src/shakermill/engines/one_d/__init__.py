"""The one-ball, one-dimensional engine of Son 2025: what it declares (``description``), its state layout and
right-hand side (``model``), the Runge–Kutta tableau and step control (``tableau``), contact landing
(``contacts``), the compiled loop with energy projection (``integrator``), the engine the solvers drive
(``engine``), and the SciPy cross-check of the same right-hand side (``reference``)."""
