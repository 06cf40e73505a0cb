"""Guidance laws: pure pursuit for the USV, leader-follower geometry for the UUV (003 ch. 3.1-3.2)."""
