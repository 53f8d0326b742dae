"""Guo et al. 2023 section 5 reproduced: experiments, recorded, and a report from them."""
