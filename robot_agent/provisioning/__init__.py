"""Making a robot's credentials: AWS IoT (boto3) or the local stack's CA, and its config file."""
