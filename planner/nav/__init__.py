"""The controller that drives an AGV (section 4, fusion): global plan, key nodes as DWA's
local targets, recoveries; the top of ``planner``.
"""
