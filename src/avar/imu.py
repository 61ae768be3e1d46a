"""IMU container (being written: see the IMU issue)."""


class IMU:  # placeholder so that avar.avar can dispatch; replaced by the IMU issue
    pass
