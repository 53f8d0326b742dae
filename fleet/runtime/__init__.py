"""The run-time: the world, the AGV nodes, the lockstep loop and the processes that run them."""
