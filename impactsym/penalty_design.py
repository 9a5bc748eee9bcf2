"""Former name of :mod:`impactsym.multibody.design`, kept for code written against 0.1.

``import impactsym.penalty_design`` gives the very module :mod:`impactsym.multibody.design`.
"""

import sys

from impactsym.multibody.design import __name__ as _target

sys.modules[__name__] = sys.modules[_target]
