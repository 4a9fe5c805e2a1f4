"""Matplotlib figures drawn from result Datasets only (no numerics here)."""
