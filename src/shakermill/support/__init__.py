"""Tools every layer may use and that know nothing of mills: atomic file writes, reading CSV input,
size limits, the version, Numba's cache, and the presenters through which lower layers show themselves."""
