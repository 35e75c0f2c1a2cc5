"""Orchestration: parameters in, :class:`~shakermill.solvers.result.Result` out. One run driver (``driver``:
chunks, budgets, progress, Ctrl-C, batch means) under the full-resolution solver (``full``) and the averaged
multiscale solver (``averaged``); the probe for coexisting attractors (``attractors``), a lone impact
(``impact``), and the dispatch by engine and solver (``simulate``)."""
