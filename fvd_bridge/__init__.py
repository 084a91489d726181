"""fvd_bridge: calibrate fluid-viscous damper (FVD) laws on test records,
explain their misfit, and export them.  Units everywhere: kN, mm, s."""

__version__ = "0.1.0"
