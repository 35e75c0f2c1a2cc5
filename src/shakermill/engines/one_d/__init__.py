"""The one-ball, one-dimensional engine of Son 2025: state layout and right-hand side (``model``), the
compiled Runge–Kutta loop with contact landing and energy projection (``integrator``), and a run set up
from parameters (``setup``)."""
