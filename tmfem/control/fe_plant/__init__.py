"""The finite-element models (MTC, SBC) as plants of a deployment controller: state
estimates, tension actuation, the sampled-data loop and the comparison of plants."""
