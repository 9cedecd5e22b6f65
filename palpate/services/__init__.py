"""The services both front ends call: the command line (``palpate.commands``) and the Python
API (``palpate.api``) hold options and printing, and call one function here that does the work:
``campaign`` (simulated campaigns), ``lab`` (a session on the bench, with ``benchmap`` its map on
the x-y stage and ``benchsamples`` its per-sample rows), ``design`` (a sensor for a range).
May import every room below the commands (the top, ``simulation``, ``lab``, ``campaigns``,
``reports``, ``faults``)."""
