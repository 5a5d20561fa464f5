"""The operator station: one web page with a live map of the fleet, the robots, the
conversation, the paper's keyboard-and-mouse panel, push-to-talk and the experiment view
(docs/station.md).

- `feed`: what the page shows, kept from the broker's messages and pushed to every page;
- `controls`: the keyboard-and-mouse panel's orders, checked against the paper's procedure;
- `assistant`: where typed and spoken requests go (the Alexa simulator, in-process or over
  the local stack's HTTP API);
- `voice`: push-to-talk: a WAV in, the transcript, the assistant's reply;
- `experiment`: the running session as the page shows it, and the participant's input
  forwarded to the session's log;
- `server`: the HTTP server (the page, its files, the API and the event stream);
- `station`: everything above wired together, for `vahr up` and `vahr station`.

It sits in the top layer beside `vahr.local` and `vahr.experiment` and never imports
`robot_agent`.
"""
