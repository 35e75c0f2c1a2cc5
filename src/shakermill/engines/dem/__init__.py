"""The several-ball, three-dimensional engine (MODEL.md section 12): what it declares (``description``),
constants and state derived from parameters (``model``), the compiled Hertz–Mindlin contacts with heat per
dissipation channel (``contacts``, on the small vector helpers of ``vectors``), the compiled velocity-Verlet
stepping (``stepper``), and the engine the solvers drive (``engine``)."""
