"""The shell-beam-cable (SBC) model of tensegrity-membrane systems (dissertation 4.3, 6.2-6.4)."""
