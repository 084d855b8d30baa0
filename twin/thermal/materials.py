"""Thermal properties of bearing steel, mineral oil and air (constants, SI).

Bearing steel AISI 52100 / 100Cr6: c_p = 475 J/(kg K), k = 46.6 W/(m K) (Harris and Kotzalas,
Essential Concepts of Bearing Technology, 5th ed. 2007, Table 3.5 of the rolling-bearing steels;
the same order as ASM Handbook vol. 1 for 52100). Mineral oil: c_p = 1900 J/(kg K), k = 0.13
W/(m K) (Harris and Kotzalas, Advanced Concepts of Bearing Technology, 2007, ch. 7 example oil;
Cameron, Basic Lubrication Theory). Air at about 40 degC and 1 atm: k = 0.0271 W/(m K),
nu = 1.70e-5 m^2/s, Pr = 0.71 (Incropera and DeWitt, Fundamentals of Heat and Mass Transfer,
Table A.4).
"""

STEEL_SPECIFIC_HEAT_J_KG_K = 475.0
STEEL_CONDUCTIVITY_W_M_K = 46.6
STEEL_EXPANSION_K_INV = 11.5e-6  # linear thermal expansion of 52100 [1/K] (Harris and Kotzalas, Table 3.5)
OIL_SPECIFIC_HEAT_J_KG_K = 1900.0
OIL_CONDUCTIVITY_W_M_K = 0.13
AIR_CONDUCTIVITY_W_M_K = 0.0271
AIR_KINEMATIC_VISCOSITY_M2_S = 1.70e-5
AIR_PRANDTL = 0.71
STEFAN_BOLTZMANN_W_M2_K4 = 5.670374419e-8
GRAVITY_M_S2 = 9.80665
