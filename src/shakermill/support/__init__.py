"""Tools every layer may use and that know nothing of mills: atomic file writes,
size limits, the version, Numba's cache, and the presenters through which lower layers show themselves."""
