"""Data generation: MimicGen demonstrations and IntervenGen interventions from a few sources."""
