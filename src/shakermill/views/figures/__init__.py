"""Figures, as PNG and SVG: of a run (:mod:`run`), its impacts (:mod:`impacts`), and of sweeps and scans
(:mod:`sweeps`); what they share in :mod:`common`."""
