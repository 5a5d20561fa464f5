"""The whole system on one machine (`vahr up`): the hosts that run where AWS would run
Lambdas (the fleet dispatcher and the announcer), the room assistant robots talk to, the
robots as processes, and `LocalSystem` composing them on the twin of AWS IoT (`vahr.twin`)
with the assistant (`vahr.assistant`). Nothing below it imports it; the station is handed to
it from above (`vahr up`)."""
