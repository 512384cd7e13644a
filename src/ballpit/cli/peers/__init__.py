"""The landing grid in ballpit and in its peers, MuJoCo and PyBullet (``ballpit bench --peers``).

``landing`` is the workload and its measures, one module per engine sets that engine up at its
fastest stable settings, ``measure`` times one landing in this process, ``rounds`` runs each landing
in its own process with the engines taking turns, and ``report`` prints, writes and plots the medians.
"""
