"""The announcer function: robots' troubles told to the person through Alexa, unprompted.

A Lambda function of its own beside the skill (`lambda/announcer`, imported as `announcer`,
handler `announcer.app.lambda_handler`), shipped in the skill's bundle. An IoT topic rule
sends the robots' events and presence to it, and an EventBridge schedule wakes it once a
minute to tell what the rate limit held back; the announcement policy (`vahr.announce`)
decides what is worth telling, with its state kept in DynamoDB between invocations; each
announcement becomes an Alexa Proactive Events API `AMAZON.MessageAlert.Activated` event
(`proactive_events`), sent with a token got with the skill's client credentials from
Secrets Manager. `aws` is the only module that calls boto3. What is not accepted raises,
so Lambda's retries and then its dead-letter queue keep the event.

Among `vahr` it imports only `vahr.protocol` and `vahr.announce`; the skill imports
neither this package nor `vahr.announce`.
"""
