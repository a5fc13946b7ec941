csfcal-display-profile 1
future_key = 3
[curve grey]
transform_gamma = 2.2
drive01,lum_cdm2
0,0.5
0.5,20
1,100
