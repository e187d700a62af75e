"""Studies of a shot, built on the engine: what can be trusted, and what to fire.

- :mod:`.check`: stability (two tiers) and where the model is stretched, before and after a run;
- :mod:`.convergence`: error against time step and run time, on a ladder of steps;
- :mod:`.design`: the v0 or geometry that gives a requested peak (and pulse);
- :mod:`.sweep`: grids and Monte Carlo of many shots on the batch kernel.

Their workbooks are written by :mod:`airgun_xl.reports`; the CLI's subcommands call them.
"""
