"""Controllers: anti-windup PID, USV/UUV loops, backstepping, pole placement, berthing, allocation."""
