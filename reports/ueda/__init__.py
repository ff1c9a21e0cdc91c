"""Figures of Ueda's oscillator results."""
