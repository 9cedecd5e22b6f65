"""The services both front ends call: the command line (``palpate.commands``) and the Python
API (``palpate.api``) hold options and printing, and call one function here that does the work.
May import every room below the commands (the top, ``simulation``, ``lab``, ``campaigns``,
``reports``, ``faults``)."""
