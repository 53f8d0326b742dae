"""The controller that drives an AGV (section 4, fusion): global plan, key nodes as DWA's
local targets, recoveries; the top of ``planner``.

``FusionController`` (``fusion``) is put together from parts with the jobs of Nav2's
``nav2_core`` interfaces and behaviour tree, each a small class in its own module:

- ``plan_keeper.PlanKeeper``: what the AGV knows of its map (the static map, the
  temporary obstacles sensed, the AGVs stopped for good, the walkers standing on the
  route) and the global plans drawn on it: the initial plan and every replan.
- ``key_node_targets.KeyNodeTargets``: which key node of the plan is DWA's local target,
  when it switches to the next (within the switch reach, later at a tight corner
  (``tight_turns``), on when gone by beside it (``passed_node``)), the route ahead.
- ``goal_checker.GoalChecker`` (Nav2's GoalChecker): arrived, within the tolerance and
  (default profile) stopped.
- ``progress_checker.ProgressChecker`` (Nav2's ProgressChecker): no progress along the
  route for the progress window is a stall.
- ``recovery_sequence.RecoverySequence``: at each stall the next recovery (replan, wait,
  back off, rotate; the commands in ``recovery``), bounded, then failed with the reason;
  coming back where its stalls have been (``old_ground.OldGround``) is no progress.
- ``turn_round.TurnRound``: the turn on the spot towards a target behind.
- ``dwa_inputs``: what DWA is given beyond its target (the route segment, kept to the
  right of an AGV coming; the braking room ahead) and the straight approach that takes
  DWA's place over the last metres to a tight corner, the goal or a waiting place.
- ``mode.Mode``: what the controller is doing between cycles (turning in place, driving,
  recovering, waiting, arrived, failed).

A control cycle (``FusionController.step``) reads top-down: observe (the trail of where
the AGV went, and where a sequence of stalls took it); check the goal (arrived, or brake
inside the tolerance); go on with a turn in place or a timed recovery under way; replan
at once when what was seen blocks the route; wait where the traffic rule holds the AGV;
check progress (a stall starts the next recovery); pick the target (switch key nodes);
plan locally (a turn round, the straight approach to a tight corner, or DWA) and command.

``warm_up`` drives a controller through a run's situations before a run, so that no
compiled kernel loads mid-run.
"""
