"""Pure physics in SI units, as small compiled functions: contact laws (Hertz, damping, heat), air
properties and convection, the vial's kinematics. No state, no time stepping."""
