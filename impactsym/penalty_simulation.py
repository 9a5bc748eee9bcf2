"""Former name of :mod:`impactsym.multibody.simulation`, kept for code written against 0.1.

``import impactsym.penalty_simulation`` gives the very module :mod:`impactsym.multibody.simulation`.
"""

import sys

from impactsym.multibody.simulation import __name__ as _target

sys.modules[__name__] = sys.modules[_target]
