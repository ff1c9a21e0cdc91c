"""Figures of the vibro-impact system's results."""
