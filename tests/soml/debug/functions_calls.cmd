# args: --break functions.soml:3
continue
bt
locals
print n
step
locals
next
next
finish
bt
frame 1
locals
print r
continue
