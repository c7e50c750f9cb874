"""igen-deploy: a policy's trials on an arm, through the safety layer and the pose estimator."""
