"""The studies of the paper, one module each; every study returns a report Section.

- :mod:`~geardyn.paper.studies.damping`: Table 2 and the ξ0, ξ1 text (bifurcation diagrams);
- :mod:`~geardyn.paper.studies.backlash`: Table 3, the impact state and the amplitude against backlash;
- :mod:`~geardyn.paper.studies.jumps`: frequency responses, the jump claims and Table 4;
- :mod:`~geardyn.paper.studies.formula`: the amplitude formula;
- :mod:`~geardyn.paper.studies.stability`: the stability condition and the orbits behind the first jump.
"""
