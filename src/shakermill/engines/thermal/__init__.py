"""The one thermal network of every engine (MODEL.md sections 4-6, 11, 12.5, 13): nodes, named heat paths
with their correlations and sources (``paths``), the network built from parameters (``network``), and the
compiled heat flows and energy balances the engines and the solvers evaluate it with (``kernel``)."""
