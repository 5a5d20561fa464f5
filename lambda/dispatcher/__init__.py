"""The dispatcher function: fleet tasks given to the best free robot on AWS.

A Lambda function of its own beside the skill (`lambda/dispatcher`, imported as
`dispatcher`, handler `dispatcher.app.lambda_handler`), shipped in the skill's bundle. It
runs the pure core of `vahr.dispatch` over three AWS adapters: the tasks in a
DynamoDB table with conditional writes (`task_table`), the candidate robots from IoT fleet
indexing's `SearchIndex` (`fleet_search`), and the commands through iot-data Publish
(`command_channel`). Three things invoke it: the skill, synchronously, to submit an order,
list the queue or cancel a task (`requests`), an IoT topic rule when a robot's shadow
says it became free (`robot_updates`), and a schedule once a minute that offers again the
commands robots never acknowledged (`reoffer`). A task it loses is told to the announcer
function (`announcer_channel`); what it does by itself goes to the audit trail
(`trail_table`). Only these five adapters call boto3.

Among `vahr` it imports only the wire contract, the domain and the dispatch core.
"""
