"""Matplotlib figures (no computation here: inputs are arrays from :mod:`ngdual.post`, or a
scene with its mesh for the two pictures every lecture starts from, :func:`plot_geometry`
and :func:`plot_von_mises`).

Every ``plot_*`` function returns a :class:`matplotlib.figure.Figure`; saving it is the
caller's choice, :func:`save_figure`. Importing this package leaves matplotlib's backend
alone: a notebook keeps its inline backend, a headless run gets Agg by matplotlib's own
fallback.

One module per kind of picture: :mod:`.fields` (element fields, von Mises), :mod:`.deformed`
(the deformed body), :mod:`.meshes`
(the triangulation, the boundary parts, the domain of Example 3.46), :mod:`.traces` (the
traces on Gamma_C), :mod:`.curves` (line plots and iteration-count grids), :mod:`.scales`
(axis labels in the scene's units, clipped colour scales), :mod:`.slides` (the slide
geometry: 16:9, 1600 x 900 px, fonts sized for it) and :mod:`.save` (files and the JSON
sidecar).

Axis labels carry the units the scene declares in its ``[units]`` table
(:class:`ngdual.scene.Units`, passed as ``units``); where it declares none a label names
the quantity only ("$x_1$", "von Mises stress"), never a made-up unit. Fields with
corner singularities take ``clip``: the colour scale ends at that percentile and the
colour bar says so.

>>> import numpy as np
>>> fig = plot_mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> type(fig).__name__
'Figure'
"""

from .curves import plot_convergence, plot_curves, plot_heatmaps
from .deformed import magnification, plot_deformed
from .fields import plot_element_field, plot_field_pair, plot_von_mises
from .meshes import plot_domain, plot_geometry, plot_mesh
from .save import figure_texts, save_figure
from .scales import CORNER_CLIP, clipped_scale, unit_label
from .slides import SLIDE_PIXELS, fit_slide, in_slides, slides
from .traces import TRACE_CLIP, corner_note, plot_contact_traces, trace_range

# in the order of the API page: the pictures of a solution, saving, the thesis' figures, the
# helpers of figure scripts that draw their own panels
__all__ = ["plot_geometry", "plot_mesh", "plot_element_field", "plot_von_mises",
           "plot_contact_traces", "plot_deformed", "plot_convergence", "save_figure",
           "figure_texts", "plot_field_pair", "plot_curves", "magnification",
           "plot_heatmaps", "plot_domain", "unit_label", "clipped_scale", "trace_range",
           "corner_note", "CORNER_CLIP", "TRACE_CLIP", "slides", "in_slides", "fit_slide",
           "SLIDE_PIXELS"]
