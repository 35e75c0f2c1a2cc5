"""Defaults that the command line's help shows, in a module that imports nothing.

The modules that use them import them from here, so that ``shakermill --help`` can print them
without importing NumPy, pandas, SciPy or Matplotlib.
"""

# The preset of a run that names none: the paper's SPEX 8000M (parameters/presets.py).
DEFAULT_PRESET = "spex8000m"
# What `calibrate --target` fits: the Table 5 quantities of the experiment (studies/measured.py, TABLE5).
TARGET_KEYS = ("theta_inf_C", "tau_min", "rate0_C_per_min", "vial_ball_ratio")
PNG_DPI = 150
REPORT_FILE = "report.html"
# The files each figure is written as.
FIGURE_FORMATS = ("png", "svg")
DEFAULT_SCHEDULER_TIMEOUT_S = 10.0
# The calibration's free keys when none are given.
DEFAULT_FREE = ("beta", "vial_mass", "h_outer", "lam")
# The 'dem' engine's: λ splits each contact's heat inside the stepper, so freeing it would re-run the
# three-dimensional mechanics at every evaluation; these three move only the thermal network.
DEM_DEFAULT_FREE = ("beta", "vial_mass", "h_outer")
# What a calibration frees by default on each thermal network, before the keys its run does not read are dropped
# (studies/calibration/calibrate.default_free): the paper's network its hand-tuned β, the vial's mass and its loss to
# the room; a real mill's ('mill-head', MODEL.md §13.2) what no source gives: the drive's heat, the clamp's heat
# capacity and its loss, as the shipped spex8000m-3d-calibrated was fitted (its outer loss is computed, h_outer is not
# read).
DEFAULT_FREE_BY_NETWORK = {"paper": DEFAULT_FREE, "mill-head": ("drive_heat", "clamp_heat_capacity", "clamp_loss")}
# The animation of a 'dem' run's balls (views/trajectories.py): a few seconds of GIF, however long the window.
ANIMATION_FILE = "trajectories.gif"
ANIMATION_FRAMES = 120
MOST_ANIMATION_FRAMES = 300
# Contacts slower than this (m/s) are not hits: a ball resting on the wall under gravity chatters at mm/s, ten
# times as often as it is hit (0.1 m/s is a free fall of 0.5 mm). The 'dem' engine's impact counts include
# that chatter, so the hit rate and speed are what compare with the 1-D model's impacts.
HIT_SPEED = 0.1
# Impacts faster than this (m/s) tell an active charge from a pack rolling on the wall (MODEL.md §14.2).
FAST_IMPACT_SPEED = 1.0
