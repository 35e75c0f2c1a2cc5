"""The parameter model: keys with units, bounds and sources, presets (data files with citations),
configuration and CSV input files, and the defaults the command line shows."""
