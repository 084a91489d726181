"""The text reports: what the terminal prints, one module per report (lmfit's
``printfuncs.py`` beside its models), each reading the object or the summary it
reports; the HTML twins are ``report/``.

    calibration.py      a calibration's fit report and interval lines (``Calibration.report``)
    diagnosis.py        a diagnosis and the ladder (``diagnose``)
    campaign.py         a campaign's or calibrate's table, Pareto set and warnings; a large series'
    production.py       a series' outliers and acceptance
    property_bounds.py  a series' upper and lower damper properties (ASCE 7)
    frames.py           a frame comparison and the dampers' sizing (``frame``)
    record.py           a record's summary (``inspect``)
    table.py            the columns they share: as wide as their widest cell

Numbers are rounded by ``report.numbers``, shared with the HTML.  This
package imports none of its modules: whoever prints a report imports that
one (``calibration/core.py`` the calibration's) without the others.
"""
