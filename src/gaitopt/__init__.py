"""gaitopt: energy-optimal walking gaits for planar multibody bipeds."""

__version__ = "0.1.0"
