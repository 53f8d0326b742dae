"""Global planning on a map: A* (traditional and improved), key nodes, the global
planner that joins them, and checks of a route against what is sensed.
"""
