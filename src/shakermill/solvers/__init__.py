"""Orchestration: parameters in, :class:`~shakermill.solvers.result.Result` out, at full resolution
(``full``) or with the averaged multiscale solver (``averaged``), and the SciPy cross-check (``reference``)."""
