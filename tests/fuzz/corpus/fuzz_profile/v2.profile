csfcal-display-profile 2
