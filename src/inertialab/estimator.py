"""The estimator contract shared by every learner (and the vibration-bias model), after
scikit-learn's (its developer guide, "Rolling your own estimator"): the keyword-only
constructor only stores its hyper-parameters under their own names, ``fit`` validates,
sets ``attr_`` attributes and returns ``self``, and anything that needs a fit raises
:class:`~inertialab.errors.NotFittedError` before it.

:class:`Estimator` gives ``get_params``/``set_params`` read from the constructor's
signature, :func:`clone` an unfitted copy with the same parameters, and
:func:`check_fitted` the one not-fitted check. Written here (not imported from
scikit-learn) because scikit-learn is not a dependency and this is forty lines.

The other calibration models are results of a study's fit, not estimators; what they
follow instead, and why, is stated in :mod:`inertialab.calib.base`.
"""

from __future__ import annotations

import copy
import inspect

from inertialab.errors import NotFittedError


class Estimator:
    """Mixin: ``get_params``/``set_params`` from the constructor's keyword parameters."""

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p.name for p in sig.parameters.values()
                if p.name != "self" and p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)]

    def get_params(self, deep: bool = False) -> dict:
        """The constructor's parameters and their current values."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params) -> Estimator:
        """Set constructor parameters by name; an unknown name is a ``ValueError``."""
        valid = set(self._param_names())
        for name, value in params.items():
            if name not in valid:
                raise ValueError(f"{type(self).__name__} has no parameter '{name}' "
                                 f"(parameters: {', '.join(sorted(valid))})")
            setattr(self, name, value)
        return self


def clone(estimator):
    """A new, unfitted estimator with deep copies of ``estimator``'s parameters."""
    params = {k: copy.deepcopy(v) for k, v in estimator.get_params().items()}
    return type(estimator)(**params)


def check_fitted(estimator, attribute: str, what: str = "predict") -> None:
    """Raise :class:`NotFittedError` unless ``estimator`` has ``attribute`` (set by fit)."""
    if getattr(estimator, attribute, None) is None:
        raise NotFittedError(f"{type(estimator).__name__}.{what} called before fit")
