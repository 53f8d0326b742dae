"""DWA's critics: the terms of its score, one per module, each behind ``base.Critic``.

A critic scores every candidate (admissible sample) of a control cycle at once, as an
array, higher being better; the choice (``planner.local.choice``) divides each critic's
scores by their sum over the candidates (Eq. 10's normalisation), multiplies them by the
critic's weight and adds them up in the profile's order. A profile
(``planner.local.behaviour``) lists the critics it runs; leaving one out of the list
turns it off.

==============  ======================================================  ==========  ===============
critic          scores                                                  profiles    weight
==============  ======================================================  ==========  ===============
``Heading``     xhead: pi - |error| between the bearing from the        paper,      ``alpha`` (0.1)
(heading.py)    trajectory's end to the target and the direction of    default
                travel; pi for a trajectory within ``reach`` of it
``Clearance``   dist: the trajectory's least clearance, capped at       paper,      ``beta`` (0.2)
(clearance.py)  ``clearance_cap``; on the final approach nearness of    default
                its end to the target instead
``Speed``       vel: the linear speed |(vx, vy)|                        paper,      ``gamma`` (0.2)
(speed.py)                                                              default
``Facing``      pi - the angle between the body heading and the         default     0.3
(facing.py)     direction of travel (not with ``free_heading``)
``OnRoute``     ``clearance_cap`` - the trajectory's largest distance   default     0.3
(route.py)      from the route's current segment (with a segment only)
==============  ======================================================  ==========  ===============

The weights of Eq. (10)'s three are the vehicle's (``DwaConfig``: Table 1's values in
brackets, set per scenario); the default profile's own critics carry theirs in the
profile. Besides the score, the default profile's steady choice takes, among the
candidates scoring within ``STEADY_TOLERANCE`` of the best, the one of least ``jerk``
(the change of the last cycle's acceleration): a tie-break, not a weighed term.
"""
