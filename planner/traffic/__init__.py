"""Traffic between AGVs: the passages found from the costmap and the zone rule every
AGV applies to the fleet's intents.
"""
