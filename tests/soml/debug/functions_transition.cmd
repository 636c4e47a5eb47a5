# args: --break-transition cell.go
continue
bt
print served
print this
step
next
locals
continue
marking
continue
