"""Pure path-planning algorithms of agv-fleet: numpy in, numbers out.

Nothing here touches processes, files (beyond reading maps) or the bus.
"""
