"""The parameter model: keys with units, bounds and sources, presets (data files with citations),
configuration files and the defaults the command line shows."""
