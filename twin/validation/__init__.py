"""Offline science around the engine: analytic references (analytic), the seed studies (studies),
the fit of the loop's thermal film law to the EHL solver (thermal_law_fit), seed 001's thrust
bearing (thrust_bearing_seed001) and the engine benchmark (bench). Not used by the runtime."""
