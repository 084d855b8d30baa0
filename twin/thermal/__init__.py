"""Thermal network of a rolling bearing in the loop of the twin.

Nodes: shaft, inner ring, balls, outer ring, housing, oil (twin.thermal.network). Conductances
from the geometry and published correlations (twin.thermal.correlations), heat capacities from
masses and specific heats (twin.thermal.materials). The network is integrated between frames by
an exact exponential step (twin.thermal.integrator), fed by the twin's own friction power, contact
by contact and source by source (twin.thermal.sources). Its temperatures set the oil viscosity
and the contacts' inlet temperature, and the rings' and balls' thermal expansion the operating
clearance (twin.thermal.expansion). A Kalman filter on the dissipation to the surroundings makes
the network follow a measured temperature (twin.thermal.estimator). `ThermalCoupling`
(twin.thermal.coupling) is what `Twin` holds.

Plain Python and numpy between frames, never in the hot loop. SI units; temperatures in K
unless the name says degC.
"""
