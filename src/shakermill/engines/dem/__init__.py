"""The several-ball, three-dimensional engine (MODEL.md section 12): constants and state derived from
parameters (``model``), the compiled velocity-Verlet stepping with Hertz–Mindlin contacts and heat per
dissipation channel (``stepper``), and a run driven from Python in budgeted chunks (``engine``)."""
