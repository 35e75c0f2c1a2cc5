"""
An hour of the SPEX 8000M in one dimension
==========================================

The default preset (``spex8000m``: the paper's mill and ball, Son 2025) for an hour with the averaged solver: the
mechanics until its means converge, then the thermal network. ``print(result)`` says what the run is in a few lines;
the summary holds every number the run table shows.
"""

from shakermill.parameters.presets import default_parameters
from shakermill.solvers.simulate import simulate
from shakermill.solvers.summary import unit_of

params = default_parameters("spex8000m", solver="averaged")
result = simulate(params)
print(result)

# %%
# The steady state is where the network would settle; the exponential is fitted to the ball over the hour. Each key
# of the summary is an attribute with its unit (``shakermill.solvers.summary``); ``value`` reads one chosen by name.
for key in ("theta_inf_C", "tau_min", "ball_steady_C", "vial_steady_C", "slowest_time_constant_min"):
    print(f"{key:28s} {result.summary.value(key):8.2f} {unit_of(key)}")

# %%
# The temperatures of paper Fig. 5a, drawn by the function ``shakermill plot`` uses.
import matplotlib.pyplot as plt  # noqa: E402

from shakermill.views.figures.run import temperature_figure  # noqa: E402

# shakermill draws on figures of its own; pyplot adopts one to show it here.
figure = plt.figure(temperature_figure(result))
