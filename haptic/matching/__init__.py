"""Matching data components against models (seed §2.3–2.6)."""
