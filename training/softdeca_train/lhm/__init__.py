"""The layered head model (paper 3.1): wraps, tet layers and S's embedding per identity."""

from softdeca_train.lhm.checks import LhmReport, check_lhm
from softdeca_train.lhm.fit import fit_lhm
from softdeca_train.lhm.model import LayeredHeadModel, LhmConfig

__all__ = ["LayeredHeadModel", "LhmConfig", "LhmReport", "check_lhm", "fit_lhm"]
