"""Control design on a plant: balanced reduction in canonical coordinates, observers, feedback
laws (LQR, SMC), exact sampling, exact closed-loop simulation, python-control views."""
