"""SoftDECA training pipeline: head template, layered head model, data, networks.

Run ``python -m softdeca_train --help`` for the steps.
"""

__version__ = "0.1.0"
