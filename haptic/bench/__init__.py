"""Benchmarks: many episodes across models, poses, noise levels and policies; tables and plots."""
