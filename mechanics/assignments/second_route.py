"""sympy's own mechanics on a scene's bodies: the second route that checks a variant's keys.

It is the engine's independent oracle (mechanics/oracle.py, also the tests' reference): V written
out from the spec's fields, the declared loads as sympy's forcelist, and sympy's LagrangesMethod.
The route shares only the model's bodies and declared loads with the derivation; the Lagrangian,
the partial velocities and the generalized forces are formed sympy's way. One copy of it, so a fix
to the reference is a fix to the keys' check.
"""

from __future__ import annotations

from mechanics.oracle import lagranges_method, loads, potential

__all__ = ["lagranges_method", "loads", "potential"]
