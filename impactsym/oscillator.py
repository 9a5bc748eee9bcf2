"""Former name of :mod:`impactsym.contact.derivation`, kept for code written against 0.1.

``import impactsym.oscillator`` gives the very module :mod:`impactsym.contact.derivation`.
"""

import sys

from impactsym.contact.derivation import __name__ as _target

sys.modules[__name__] = sys.modules[_target]
