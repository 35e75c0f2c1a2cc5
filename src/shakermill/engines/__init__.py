"""Engines: the equations of motion and heat of one mill model and the compiled loop that integrates
them, one subpackage per engine (``one_d``: one ball in one dimension), and the run budget they share."""
