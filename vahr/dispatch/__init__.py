"""Fleet task assignment: orders, tasks, the cost of a robot for a task, and the
dispatcher both hosts run (the local stack and the dispatcher Lambda)."""
