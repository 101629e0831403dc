"""Minimum-time optimal control problems solved with CasADi and IPOPT.

Two independent numerical references for the closed form of
:mod:`ptoverify.model.mintime` (DESIGN.md, reference 2):

* :class:`TwoPhaseOCP` -- the input is fixed at -s w_max, then +s w_max; the
  phase durations t1, t2 >= 0 are the only variables and the state is exact
  inside each phase (the flow of eq. 7 as a CasADi expression).  The side s
  comes from the sign of the switching function (eqs. 9, 11) by default, or,
  with ``side="both"``, from solving both sides and keeping the converged,
  faster one.
* :class:`CollocationOCP` -- single-phase direct collocation (Radau, degree 3)
  over N intervals with a free final time, a piecewise-constant input
  |u| <= w_max per interval, and a valid lower bound on t_f.

Both problems are written in the dimensionless variables of eq. (1)::

    z1 = a x1 / w_max,   z2 = x2 / w_max,   v = u / w_max,   tau = a t
    dz1/dtau = z2,       dz2/dtau = -z2 + v,  |v| <= 1

so that one NLP (one ``nlpsol`` and one set of CasADi functions) serves every
plant and every state: the state enters as a parameter, the plant only through
the scaling.  The solvers are built once per process and per option set
(memoized with :func:`ptoverify.model.memo.memo`).  The two-phase solver starts from
its previous solution (warm; the 2x2 system has one solution, so the result
does not depend on the start); collocation starts cold by default (see
:class:`CollocationOCP`) so that a result does not depend on call order.

A solve that IPOPT does not finish with ``Solve_Succeeded`` returns
``success=False`` and the IPOPT status in ``status``; such a number is
unverified and must never be used as a reference.
"""

from .collocation import CollocationOCP, radau_weights
from .convergence import ConvergenceStudy, convergence_study
from .twophase import TwoPhaseOCP
from .types import OCPResult, resimulate

__all__ = [
    "CollocationOCP",
    "ConvergenceStudy",
    "OCPResult",
    "TwoPhaseOCP",
    "convergence_study",
    "radau_weights",
    "resimulate",
]
