"""The Alexa skill (ask-sdk-core). `skill.app.lambda_handler` is the Lambda entry point."""
