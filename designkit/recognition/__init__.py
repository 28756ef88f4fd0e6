"""Recognition: the paper's features and SVM, and the ideal observer (the bound no classifier beats).

Modules: :mod:`~designkit.recognition.features` (raw samples + local slope),
:mod:`~designkit.recognition.svm` (standardized features, linear SVM, k-fold F1),
:mod:`~designkit.recognition.ideal` (closed form for shared-shape models),
:mod:`~designkit.recognition.ideal_mc` (Monte Carlo for the others),
:mod:`~designkit.recognition.scores` (what they share). Import from the
modules: this package loads nothing heavy on its own.
"""

__all__: list[str] = []
