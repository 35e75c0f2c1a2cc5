"""
Ten balls in a planetary bowl: the stress-energy spectrum
=========================================================

The ``pulverisette7`` preset (a 45 ml steel bowl on a 140 mm sun disc, 1 : −2 at 800 rpm, ten 10 mm steel balls;
dimensions and friction are stated assumptions: ``shakermill presets pulverisette7``) for a quarter of a second at
full resolution: long enough to see the charge's impacts, not its heating, which takes the averaged solver.
"""

from shakermill.parameters.presets import default_parameters
from shakermill.solvers.simulate import simulate

params = default_parameters("pulverisette7", solver="full", duration=0.25)
result = simulate(params)
print(result)

# %%
# How the heat is made, by dissipation channel, and how hard the balls hit: the spectrum of the energy each impact
# dissipates (Kwade's stress energy), which decides whether a reaction can be activated.
print(f"heat power {result.summary.heat_power_W:.3g} W; impacts per second {result.summary.impacts.rate_hz:.0f}")

import matplotlib.pyplot as plt  # noqa: E402

from shakermill.views.figures.impacts import spectrum_figures  # noqa: E402

figure = plt.figure(spectrum_figures(result)["stress_energy_spectrum"])
