"""Option types shared by commands, so that names, units and help agree everywhere."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

Json = Annotated[bool, typer.Option("--json", help="Print the result as JSON on stdout.")]
SensorOpt = Annotated[str, typer.Option(
    "--sensor", help="Sensor preset name ('paper') or a sensor YAML file written by calibration.")]
Noise = Annotated[float, typer.Option("--noise", help="Noise sigma per sample [°C].")]
DeltaT = Annotated[float, typer.Option(
    "--delta-t", help="Sensor minus object temperature before contact [°C].")]
Ambient = Annotated[float, typer.Option("--ambient", help="Ambient (object) temperature [°C].")]
Contact = Annotated[float, typer.Option("--contact", help="Contact time [s].")]
Seed = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same trials).")]
Threshold = Annotated[float, typer.Option(
    "--threshold", help="F1 at or above which a pair counts as distinguishable (the paper's Phi).")]
E1 = Annotated[Optional[float], typer.Option("--e1", help="Effusivity of the first object [J s^-1/2 K^-1 m^-2].")]
E2 = Annotated[Optional[float], typer.Option("--e2", help="Effusivity of the second object [J s^-1/2 K^-1 m^-2].")]
Width = Annotated[float, typer.Option(
    "--width", help="Width of each effusivity class [e, e+width) [J s^-1/2 K^-1 m^-2] (paper: 80).")]
Trials = Annotated[int, typer.Option("--trials", help="Simulated touches per class.")]
Folds = Annotated[int, typer.Option("--folds", help="Cross-validation folds.")]
