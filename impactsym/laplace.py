"""Former name of :mod:`impactsym.symbolic.laplace`, kept for code written against 0.1.

``import impactsym.laplace`` gives the very module :mod:`impactsym.symbolic.laplace`.
"""

import sys

from impactsym.symbolic.laplace import __name__ as _target

sys.modules[__name__] = sys.modules[_target]
