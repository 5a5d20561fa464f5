"""The dispatcher function: fleet tasks given to the best free robot on AWS.

A Lambda function of its own beside the skill (`lambda/dispatcher`, imported as
`dispatcher`, handler `dispatcher.app.lambda_handler`), shipped in the skill's bundle. It
runs the pure core of `vahr.dispatch` over three AWS adapters: the tasks in a
DynamoDB table with conditional writes (`task_table`), the candidate robots from IoT fleet
indexing's `SearchIndex` (`fleet_search`), and the commands through iot-data Publish
(`command_channel`). Two things invoke it: the skill, synchronously, to submit an order,
list the queue or cancel a task (`requests`), and an IoT topic rule when a robot's shadow
says it became free (`robot_updates`). Only the three adapters call boto3.

Among `vahr` it imports only `vahr.protocol`.
"""
