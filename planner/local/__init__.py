"""Local planning: the dynamic window approach (section 3) and the default profile's
behaviours around it (lanes, yielding, keeping right, evasion).
"""
