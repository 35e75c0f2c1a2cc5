"""Studies built on many runs: sweeps (local pool or Dask, resumable), bifurcation scans,
calibration and validation against the experiment."""
