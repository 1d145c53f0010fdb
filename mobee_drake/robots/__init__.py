"""The robots as Drake models with MoBeE's overlay: the iCub of icub-models (``icub``,
``model_cache``), robots of MoBeE's XML format (``zero_position``), the overlay schema
(``overlay``), how a model and its overlay are put into a plant (``assembly``,
``scenario_robot``), and the robot as its controllers see it (``controlled_robot``)."""
