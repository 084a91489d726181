"""What a person reads: HTML views of calibrations and diagnoses (a notebook's ``_repr_html_``)."""
