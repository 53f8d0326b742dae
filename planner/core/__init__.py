"""The vocabulary every layer shares: errors, input limits, statuses, profiles, the
motion model (Eq. 4) and polyline geometry. Imports nothing of ``planner``.
"""
