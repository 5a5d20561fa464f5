"""The AWS CDK app: `app.py` composes the stacks; `constructs/` holds one construct per resource family."""
