"""igen-lerobot."""
