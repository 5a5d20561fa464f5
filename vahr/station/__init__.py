"""The operator station: one web page with a live map of the fleet, the robots, the
conversation, the paper's keyboard-and-mouse panel, push-to-talk and the experiment view
(docs/station.md).

- `feed`: what the page shows, kept from the broker's messages and pushed to every page;
- `controls`: the keyboard-and-mouse panel's orders, checked against the paper's procedure;
- `desk`: the running experiment session as the station sees it, and the participant's
  input forwarded to the session's log;
- `voice` and `vocabulary`: push-to-talk (a WAV in, the transcript, the assistant's reply)
  and the sentences its recognizer listens for;
- `app`: the API's routes, apart from HTTP; `errors`: the one error a request is refused
  with;
- `server`: the HTTP server (the page, its files, the API and the event stream);
- `contract`: the page's side of the messages, written from `vahr.station.page_messages`;
- `station`: everything above wired together; `deployment`: a station built for `vahr up`
  (in its process) or for `vahr station` (against any deployment).

Typed and spoken requests go to an assistant (`vahr.plumbing.client.Assistant`). The station
sits in the top layer above `vahr.experiment` and `vahr.local` (docs/architecture.md): it
imports them, they never import it, and it reaches the Alexa simulator only through what
`vahr.assistant` exports. It never imports `robot_agent`.
"""
