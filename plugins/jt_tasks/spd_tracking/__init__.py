"""``task=spd_tracking``: SPD mocap tracking over time steps, FPS and SPD share (thesis 001 §2.4).

Modules: ``motions`` (reference motions in generalised coordinates: DeepMimic clips, the snakes'
travelling wave), ``tracking`` (one run at one time step, the error measure), ``artifacts``
(HDF5, plot, filmstrip), ``task`` (the ``Task`` plugin ``SPDTrackingTask``). Nothing heavy is
imported at module level.
"""
