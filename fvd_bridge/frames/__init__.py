"""The SAC benchmark frames as data (``buildings``) and as OpenSees commands
(``model``), their transient analysis (``transient``, ``analysis``), the FMU
co-simulation (``cosim``) and the damper comparison (``compare``, ``outputs``).
Ground motions: ``fvd_bridge.records.motions``."""
