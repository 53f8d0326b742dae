"""Maps: the grid in the world frame, its loaders, the distance field, the costmap and
what an AGV's body needs (clearance). Imports only ``planner.core``.
"""
