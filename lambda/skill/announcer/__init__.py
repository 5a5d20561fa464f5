"""The skill's announcer: robots' troubles told to the person through Alexa, unprompted.

An IoT topic rule sends the robots' events and presence to `announcer.app.lambda_handler`;
the announcement policy (`vahr.announce`) decides what is worth telling, with its state
kept in DynamoDB between invocations (`store`); each announcement becomes an Alexa
Proactive Events API `AMAZON.MessageAlert.Activated` event (`proactive_events`), sent with
a token got with the skill's client credentials from Secrets Manager (`secrets`). What is
not accepted raises, so Lambda's retries and then its dead-letter queue keep the event.
"""
