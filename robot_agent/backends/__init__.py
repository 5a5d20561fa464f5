"""Navigation backends behind one port: `sim` (kinematic simulator) and `ros1` (move_base)."""
