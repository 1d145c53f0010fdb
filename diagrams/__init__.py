"""The shipped scenarios, addressable by name (``mobee-drake run reach_around_ball``)."""
