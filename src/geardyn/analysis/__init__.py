"""Analyses built on the integrator: steady response, chaos diagnostics, sweeps, periodic orbits."""
