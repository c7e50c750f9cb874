"""Arm driver backends: each imports its robot library only when built."""
