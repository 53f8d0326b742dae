"""Local planning: the dynamic window approach (section 3) as parts, and the default
profile's behaviours around it (lanes, yielding, keeping right, evasion).

One control cycle (``dwa.DwaPlanner.plan``): ``samples`` (the ``window``, the ``rollout``,
their ``clearance``) -> ``filters`` (``admissible``: Eq. 7, ...) -> ``fallback`` when
nothing is left -> ``critics`` scoring the ``candidates`` -> ``choice``. Which filters and
critics run, with which weights, is the profile (``behaviour``).
"""
