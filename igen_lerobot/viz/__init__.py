"""Rerun views of igen data: live while collecting, generating, evaluating or deploying, and offline."""
