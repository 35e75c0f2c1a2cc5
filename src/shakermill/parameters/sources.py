"""The sources the keys' defaults cite most (``parameters/groups/``, the presets)."""

PAPER = "Son 2025, Mathematics 13, 446"
