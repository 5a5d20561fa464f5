"""The AWS CDK app: `app.py` composes the stacks; `constructs/` holds one construct per
resource family; `lambda_asset.py` builds the skill's code bundle."""
