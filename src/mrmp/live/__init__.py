"""Live mode: one OS process per robot, real time, real sockets (UDP or Zenoh), and a referee process.

The robot brain is the same :class:`~mrmp.robot.robot.Robot` the simulator
runs; this layer owns the sockets, threads, clocks and bodies.
"""
