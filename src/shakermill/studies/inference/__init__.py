"""One way to infer, for every study that does: a prior over named keys (:mod:`prior`), a design of runs over it
(:mod:`design`), a surrogate of what the runs give with its held-out Q² (:mod:`surrogate`), one sampler (emcee,
:mod:`sampler`) and one posterior type (:mod:`posterior`). They know nothing of mills: a calibration, an ensemble or
an inverse design states its keys as a :class:`~prior.Prior` and its measurements or targets as a log-probability."""
