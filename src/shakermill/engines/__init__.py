"""Engines: the equations of motion and heat of one mill model and the compiled loop that integrates them, one
subpackage per engine (``one_d``: one ball in one dimension; ``dem``: several balls in three), what every
engine declares and does (``interface``), the engines by name (``registry``), the one thermal network
(``thermal``), and what they share: the run budget, the chunked compiled calls, the status codes and the
records of a run."""
