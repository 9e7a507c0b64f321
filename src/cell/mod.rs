//! Robots, their placements in the world, and the exact check of a whole cell (thesis 2.3, 3.1; SPEC §1, §5).
