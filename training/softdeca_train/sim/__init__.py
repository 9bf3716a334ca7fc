"""φ† on real heads: the layered head model turned into the native simulator's mesh, and
frames (ARKit weights, takes) turned into its inputs."""

from softdeca_train.sim.head import HeadSimulation, build_head_simulation

__all__ = ["HeadSimulation", "build_head_simulation"]
